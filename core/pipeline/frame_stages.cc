#include "core/pipeline/frame_stages.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include "core/pipeline/frame_budget.h"
#include "core/pipeline/parallel.h"
#include "core/pipeline/pipeline_params.h"
#include "core/proposals/greedy_nms.h"
#include "core/proposals/window_grid.h"

namespace tod {

using Clock = std::chrono::steady_clock;

Result<OcclusionEdges> ComputeOcclusionEdges(const cv::Mat3b& image,
                                             const MultilayerRegions& regions,
                                             const EdgeSource& edges,
                                             const OcclusionClassifier* classifier,
                                             const PipelineParams& params, bool enhance,
                                             StageTimer* timer, const FrameBudget* budget) {
  // Marks a stage boundary; true when the timer's check asks to stop here.
  auto mark = [timer](const char* stage) {
    if (timer != nullptr) timer->Mark(stage);
    return timer != nullptr && !timer->stopped().ok();
  };
  OcclusionEdges out;
  out.r1 = ClipToImage(regions.layers.front(), image.cols, image.rows);
  out.crop = image(out.r1.rect());
  out.base_edge = edges.Compute(out.crop);
  CorrectSampledPrior(out.base_edge, params.prior_correction.edge_odds);
  // §2.2 single pass: Ê(p) = n(p) E(p), n(p) = number of layers containing p. Each inner layer
  // adds the same map once more over its rectangle.
  out.enhanced = out.base_edge.clone();
  if (enhance) {
    for (int k = 1; k < regions.num_layers(); ++k) {
      const Box inner = Intersect(regions.layers[k], out.r1);
      if (inner.empty()) continue;
      const cv::Rect local(inner.x - out.r1.x, inner.y - out.r1.y, inner.w, inner.h);
      out.enhanced(local) += out.base_edge(local);
    }
  }
  if (mark("edges")) return out;
  Result<Superpixels> superpixels =
      ComputeStickySuperpixels(out.crop, out.enhanced, params.superpixels);
  if (!superpixels.ok()) return superpixels.status();
  out.superpixels = std::move(superpixels).value();
  if (mark("superpixels")) return out;
  if (classifier != nullptr) {
    const OcclusionPaintOptions paint{
        .screening = params.occlusion_screening,
        .deadline = budget != nullptr ? budget->OcclusionDeadline() : Clock::time_point::max()};
    Result<cv::Mat1f> occlusion =
        classifier->Paint(out.crop, out.enhanced, out.superpixels, paint, &out.occlusion_trees);
    if (!occlusion.ok()) return occlusion.status();
    out.occlusion = std::move(occlusion).value();
    out.occlusion_cut_short = out.occlusion_trees < classifier->num_trees();
    CorrectSampledPrior(out.occlusion, params.prior_correction.occlusion_odds);
    (void)mark("occlusion");  // the caller checks timer->stopped() after the last stage
  }
  return out;
}

cv::Mat1f RegionEdgeMap(const OcclusionEdges& oaocc, const MultilayerRegions& regions, int k) {
  const Box region = Intersect(regions.layers[k], oaocc.r1);
  if (region.empty()) return {};
  const cv::Rect local(region.x - oaocc.r1.x, region.y - oaocc.r1.y, region.w, region.h);
  cv::Mat1f map = oaocc.occlusion(local).clone();
  if (k > 0) ClearCropBorderEdges(map);
  return map;
}

RegionProposals ProposeRegionBoxes(const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                                   const EdgeBoxParams& box_params, int k, bool multistride,
                                   const SizeFilter* size_filter, EdgeBoxStats* stats) {
  if (stats != nullptr) *stats = EdgeBoxStats{};
  RegionProposals out;
  cv::Mat1f map = RegionEdgeMap(oaocc, regions, k);
  if (map.empty()) return out;
  out.edge_max = MaxFiniteValue(map);
  map = NormaliseToMax(map);
  const EdgeBoxParams params = RegionBoxParams(box_params, k, regions.num_layers(), multistride);
  const Box region = Intersect(regions.layers[k], oaocc.r1);
  const bool filtered = size_filter != nullptr && size_filter->enabled;
  // Windows that cannot end as a kept box are not scored. Unlike the authors' order (NMS, the
  // max_boxes cut, then the filter), filtered boxes thus neither suppress kept ones in NMS nor
  // take places under max_boxes.
  std::optional<WindowAdmission> admission;
  if (filtered) admission.emplace(*size_filter, region.y);
  for (ScoredBox b : ScoreEdgeBoxes(map, params, stats, admission ? &*admission : nullptr)) {
    b.box.x += region.x;
    b.box.y += region.y;
    if (filtered && !size_filter->Keep(b.box)) continue;
    out.boxes.push_back(b);
  }
  return out;
}

EdgeBoxParams RegionBoxParams(const EdgeBoxParams& box_params, int k, int num_layers,
                              bool multistride) {
  EdgeBoxParams params = box_params;
  params.stride_factor =
      multistride ? static_cast<float>(num_layers - k) / static_cast<float>(num_layers) : 1.f;
  return params;
}

namespace {

// Per region, the factor that puts its scores on the scale of the region whose map peaks
// highest (R1, which holds the others): edge_max / the largest edge_max; 1 when no map has an
// edge.
std::vector<float> CommonScoreScales(const std::vector<RegionProposals>& per_region) {
  float largest = 0.f;
  for (const RegionProposals& r : per_region) largest = std::max(largest, r.edge_max);
  std::vector<float> scales(per_region.size(), 1.f);
  if (largest <= 0.f) return scales;
  for (std::size_t k = 0; k < per_region.size(); ++k) scales[k] = per_region[k].edge_max / largest;
  return scales;
}

}  // namespace

ProposalSet MergeRegionBoxes(const std::vector<RegionProposals>& per_region, float merge_iou) {
  std::vector<std::pair<ScoredBox, int>> merged;
  int min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  for (std::size_t k = 0; k < per_region.size(); ++k)
    for (const ScoredBox& b : per_region[k].boxes) {
      if (merged.empty()) min_x = max_x = b.box.x, min_y = max_y = b.box.y;
      min_x = std::min(min_x, b.box.x), max_x = std::max(max_x, b.box.x);
      min_y = std::min(min_y, b.box.y), max_y = std::max(max_y, b.box.y);
      merged.emplace_back(b, static_cast<int>(k));
    }
  std::stable_sort(merged.begin(), merged.end(),
                   [](const auto& a, const auto& b) { return a.first.score > b.first.score; });
  ProposalSet out;
  out.boxes.reserve(merged.size());
  out.layer.reserve(merged.size());
  out.layer_scale = CommonScoreScales(per_region);
  const bool suppress = merge_iou < 1.f;
  GreedyNms nms(merge_iou, static_cast<int>(merged.size()), min_x, min_y, max_x, max_y);
  for (const auto& [box, k] : merged) {
    if (suppress && !nms.Offer(box)) continue;
    out.boxes.push_back(box);
    out.layer.push_back(k);
  }
  return out;
}

std::vector<Box> RankedOnCommonScale(const ProposalSet& proposals) {
  const auto scale_of = [&](std::size_t i) {
    const int k = proposals.layer[i];
    return k < static_cast<int>(proposals.layer_scale.size()) ? proposals.layer_scale[k] : 1.f;
  };
  std::vector<std::pair<float, std::size_t>> keyed(proposals.boxes.size());
  for (std::size_t i = 0; i < keyed.size(); ++i)
    keyed[i] = {proposals.boxes[i].score * scale_of(i), i};
  std::stable_sort(keyed.begin(), keyed.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Box> ranked;
  ranked.reserve(keyed.size());
  for (const auto& [key, i] : keyed) ranked.push_back(proposals.boxes[i].box);
  return ranked;
}

ProposalOptions DetectorProposalOptions(const PipelineParams& params, int layers) {
  ProposalOptions options;
  options.layers_used = layers;
  options.multistride = params.multistride;
  options.size_filter = params.size_filter;
  options.merge_iou = params.region_merge_iou;
  return options;
}

namespace {

// Grid windows of each region the proposals use (0 for a region outside R1): the regions' shares
// of the proposal stage's time.
std::vector<double> RegionWindowCounts(const OcclusionEdges& oaocc,
                                       const MultilayerRegions& regions,
                                       const EdgeBoxParams& box_params, int used,
                                       bool multistride) {
  std::vector<double> windows(used, 0.0);
  for (int k = 0; k < used; ++k) {
    const Box region = Intersect(regions.layers[k], oaocc.r1);
    if (region.empty()) continue;
    windows[k] = static_cast<double>(CountWindows(
        region.w, region.h, RegionBoxParams(box_params, k, regions.num_layers(), multistride)));
  }
  return windows;
}

// Region indexes, most windows first: the order in which concurrent workers pick regions up (the
// windows are the cost known before the scan; the rest depends on the region's content).
std::vector<int> LargestFirst(const std::vector<double>& windows) {
  std::vector<int> order(windows.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return windows[a] > windows[b]; });
  return order;
}

}  // namespace

FrameRegionProposals ProposeRegions(const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                                    const EdgeBoxParams& box_params, const ProposalOptions& options,
                                    const SizeFilter& size_filter) {
  const int used = std::clamp(options.layers_used, 1, regions.num_layers());
  const std::vector<double> windows =
      RegionWindowCounts(oaocc, regions, box_params, used, options.multistride);
  const SizeFilter* filter = options.size_filter ? &size_filter : nullptr;
  std::vector<RegionProposals> per_region(used);
  std::vector<EdgeBoxStats> region_stats(used);
  const auto propose = [&](int k, Clock::time_point deadline) {
    EdgeBoxParams params = box_params;
    params.threads = options.threads;
    params.deadline = deadline;
    per_region[k] = ProposeRegionBoxes(oaocc, regions, params, k, options.multistride, filter,
                                       &region_stats[k]);
  };
  // Several threads: up to that many regions run side by side, each scanned with all of them.
  // A region's own work (its edge groups, the selection of windows to refine, its NMS) is serial,
  // so one region at a time left the other cores idle for a third of the stage; splitting the
  // threads between the regions instead left them idle once the cheaper regions were done (a
  // region's cost depends on its content, not only on its windows). The scheduler interleaves
  // the threads; the boxes do not depend on it: each region's scan is the same whichever thread
  // runs which of its chunks.
  const int workers = std::min(std::max(1, options.threads), used);
  if (workers > 1) {
    const std::vector<Clock::time_point> deadlines = PlannedInTurn(options.deadline, windows);
    const std::vector<int> order = LargestFirst(windows);
    for (const Status& s : ParallelFor(used, workers, [&](int j) {
           propose(order[j], deadlines[order[j]]);
           return Status::Ok();
         }))
      if (!s.ok()) throw std::runtime_error(s.ToString());
  } else {
    // One thread: near to far, each region by its share of the time left when it starts.
    double windows_left = 0;
    for (const double w : windows) windows_left += w;
    for (int k = 0; k < used; ++k) {
      const Clock::time_point deadline =
          ShareOfRemaining(options.deadline, windows[k], windows_left);
      windows_left -= windows[k];
      propose(k, deadline);
    }
  }
  FrameRegionProposals out;
  out.per_region = std::move(per_region);
  for (int k = 0; k < used; ++k)
    if (region_stats[k].truncated) out.truncated_regions.push_back(k);
  out.stats = std::move(region_stats);
  return out;
}

ProposalSet ProposeBoxes(const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                         const EdgeBoxParams& box_params, const ProposalOptions& options,
                         const SizeFilter& size_filter) {
  return MergeFrameRegions(ProposeRegions(oaocc, regions, box_params, options, size_filter),
                           options.merge_iou);
}

ProposalSet MergeFrameRegions(const FrameRegionProposals& found, float merge_iou) {
  ProposalSet out = MergeRegionBoxes(found.per_region, merge_iou);
  out.truncated_regions = found.truncated_regions;
  return out;
}

}  // namespace tod
