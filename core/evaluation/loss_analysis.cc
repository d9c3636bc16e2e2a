#include "core/evaluation/loss_analysis.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <mutex>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <utility>

#include "core/datasets/dataset_factory.h"
#include "core/features/mask_iou.h"
#include "core/features/sample_selection.h"
#include "core/metrics/pixel_histogram_metrics.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/parallel.h"

namespace tod {
namespace {

constexpr float kEdgeOn = 0.1f;  // Edge Boxes' edgeMinMag: weaker pixels are not edges (§4.2)

// Share of the instance's contour pixels (mask pixels with a 4-neighbour outside the mask) that
// have an edge pixel of `map` (R1-crop coordinates) within one pixel.
double ContourCoverage(const ObstacleInstance& inst, const cv::Mat1b& edge_near, const Box& r1) {
  cv::Mat1b padded;
  cv::copyMakeBorder(inst.mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  long long contour = 0, covered = 0;
  for (int y = 0; y < inst.box.h; ++y) {
    for (int x = 0; x < inst.box.w; ++x) {
      if (!padded(y + 1, x + 1)) continue;
      if (padded(y, x + 1) && padded(y + 2, x + 1) && padded(y + 1, x) && padded(y + 1, x + 2))
        continue;
      ++contour;
      const int cx = inst.box.x + x - r1.x, cy = inst.box.y + y - r1.y;
      if (cx >= 0 && cy >= 0 && cx < edge_near.cols && cy < edge_near.rows && edge_near(cy, cx))
        ++covered;
    }
  }
  return contour > 0 ? static_cast<double>(covered) / contour : 0.0;
}

cv::Mat1b EdgesDilatedByOne(const cv::Mat1f& map) {
  cv::Mat1b on = map > kEdgeOn;
  cv::dilate(on, on, cv::Mat1b::ones(3, 3));
  return on;
}

double BestIoU(const std::vector<ScoredBox>& boxes, const Box& gt) {
  double best = 0;
  for (const ScoredBox& b : boxes) best = std::max(best, BoxIoU(b.box, gt));
  return best;
}

int FirstHit(const std::vector<Box>& ranked, const Box& gt, double iou, int top_n) {
  const int n = std::min<int>(top_n, static_cast<int>(ranked.size()));
  for (int r = 0; r < n; ++r)
    if (BoxIoU(ranked[r], gt) >= iou) return r;
  return -1;
}

double Share(const cv::Mat1f& map) {
  return map.empty() ? 0.0 : static_cast<double>(cv::countNonZero(map > kEdgeOn)) / map.total();
}

// The three scorings of PixelApBreakdown, in its order.
constexpr int kApScorings = 3;

struct FrameResult {
  FrameWork work;
  std::vector<ObstacleFate> fates;
  std::array<cv::Mat1f, kApScorings> maps;  // the paper's map under each scoring
};

// The fused scores of `proposals` compared with where the obstacles are (FrameWork's score
// fields), and the paper's map under the three scorings of PixelApBreakdown.
Status ScoreAgainstObstacles(const ModelBundle& bundle, const Sample& s,
                             const MapSuperpixels& superpixels,
                             const std::vector<ScoredBox>& proposals,
                             const std::vector<float>& fused, FrameResult& out) {
  auto table = MaskIoUTable::Build(s.instances);
  if (!table.ok()) return table.status();
  const MaskPixelCounter obstacle_pixels(s.obstacle);
  const std::size_t n = proposals.size();
  std::vector<bool> covers(n);
  std::vector<float> mask_iou(n);
  FrameWork& w = out.work;
  for (std::size_t j = 0; j < n; ++j) {
    covers[j] = obstacle_pixels.Count(proposals[j].box) > 0;
    mask_iou[j] = static_cast<float>(table->MaxIoU(proposals[j].box));
    float& best = covers[j] ? w.best_obstacle_box_score : w.best_false_box_score;
    best = std::max(best, fused[j]);
  }
  for (std::size_t j = 0; j < n; ++j)
    w.false_boxes_above += !covers[j] && fused[j] > w.best_obstacle_box_score;
  // Perfect regressors: both predict the target they regress, gated and fused as served.
  const std::vector<float> perfect = FuseScores(mask_iou, mask_iou, bundle.params.fusion);
  std::array<std::vector<ScoredBox>, kApScorings> scored;
  for (auto& boxes : scored) boxes.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    scored[0][j] = {proposals[j].box, fused[j]};
    scored[1][j] = {proposals[j].box, covers[j] ? fused[j] : 0.f};
    scored[2][j] = {proposals[j].box, perfect[j]};
  }
  for (int k = 0; k < kApScorings; ++k) {
    Result<cv::Mat1f> map = AccumulateProbabilityMap(scored[k], s.image.size(),
                                                     bundle.params.probability_map, &superpixels);
    if (!map.ok()) return map.status();
    out.maps[k] = std::move(map).value();
  }
  return Status::Ok();
}

// Every region's boxes without the size filter (the variant that shows what the filter drops),
// on the detector's own edges; with windows_scored the detector's (filtered) scan's count.
std::vector<ScoredBox> UnfilteredBoxes(const ModelBundle& bundle, const FrameTrace& trace) {
  std::vector<ScoredBox> unfiltered;
  const int layers = trace.geometry.regions.num_layers();
  for (int k = 0; k < layers; ++k) {
    const RegionProposals all =
        ProposeRegionBoxes(trace.oaocc, trace.geometry.regions, bundle.params.boxes, k,
                           bundle.params.multistride, nullptr);
    unfiltered.insert(unfiltered.end(), all.boxes.begin(), all.boxes.end());
  }
  return unfiltered;
}

Result<FrameResult> AnalyseFrame(const ObstacleDetector& detector, const Sample& s,
                                 const LossAnalysisOptions& options) {
  const ModelBundle& bundle = detector.bundle();
  FrameResult out;
  FrameTrace trace;
  const Result<Detection> detected = detector.Detect(s.image, DetectOptions{}, &trace);
  if (!detected.ok()) return detected.status();
  const OcclusionEdges& oaocc = trace.oaocc;
  const FrameGeometry& geo = trace.geometry;
  const std::vector<RegionProposals>& filtered = trace.regions.per_region;
  const std::vector<ScoredBox> unfiltered =
      bundle.params.size_filter ? UnfilteredBoxes(bundle, trace) : std::vector<ScoredBox>{};
  long long windows_scored = 0;  // as the detector scores them (size filter admission on)
  for (const EdgeBoxStats& stats : trace.regions.stats) windows_scored += stats.windows_visited;
  const RegressedProposals& reg = trace.regressed;
  const std::vector<Box> by_objectness = RankedOnCommonScale(reg.proposals);
  std::vector<float> fused(trace.fused.size());
  for (std::size_t i = 0; i < fused.size(); ++i) fused[i] = trace.fused[i].score;
  std::vector<int> order(fused.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return fused[a] > fused[b]; });
  std::vector<Box> by_fused;
  for (int i : order) by_fused.push_back(reg.proposals.boxes[i].box);
  if (Status st = ScoreAgainstObstacles(bundle, s, trace.map_superpixels(), reg.proposals.boxes,
                                        fused, out);
      !st.ok())
    return st;

  out.work.frame = s.name;
  out.work.base_edge_density = Share(oaocc.base_edge);
  out.work.occlusion_density = Share(oaocc.occlusion);
  out.work.superpixels = oaocc.superpixels.count;
  out.work.proposals = static_cast<long long>(by_objectness.size());
  out.work.windows_scored = windows_scored;

  const cv::Mat1b base_near = EdgesDilatedByOne(oaocc.base_edge);
  const cv::Mat1b occlusion_near = EdgesDilatedByOne(oaocc.occlusion);
  const std::vector<int> limits = geo.regions.RangeLimits();
  for (const ObstacleInstance& inst : s.instances) {
    ObstacleFate f;
    f.frame = s.name;
    f.box = inst.box;
    f.pixels = inst.pixel_count();
    f.range = VerticalRangeIndex(BottomRow(inst.box), limits);
    f.in_r1 = Intersect(inst.box, oaocc.r1) == inst.box;
    f.contour_base_edges = ContourCoverage(inst, base_near, oaocc.r1);
    f.contour_occlusion = ContourCoverage(inst, occlusion_near, oaocc.r1);
    double best_filtered = 0;
    for (const auto& region_boxes : filtered)
      best_filtered = std::max(best_filtered, BestIoU(region_boxes.boxes, inst.box));
    f.best_iou_filtered = best_filtered;
    // Without a size filter the detector's own boxes are the unfiltered ones.
    f.best_iou_unfiltered =
        bundle.params.size_filter ? BestIoU(unfiltered, inst.box) : best_filtered;
    f.proposal_rank = FirstHit(by_objectness, inst.box, options.hit_iou, options.top_n);
    f.regressed_rank = FirstHit(by_fused, inst.box, options.hit_iou, options.top_n);
    out.fates.push_back(f);
  }
  return out;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The boxes' fused scores against the obstacles, and PixelApBreakdown, as text.
std::string FormatScoreComparison(const LossAnalysis& a) {
  std::vector<double> on_obstacle, on_none;
  int outranked = 0;
  for (const FrameWork& w : a.frames) {
    on_obstacle.push_back(w.best_obstacle_box_score);
    on_none.push_back(w.best_false_box_score);
    outranked += w.false_boxes_above > 0;
  }
  char line[320];
  std::snprintf(line, sizeof line,
                "Fused scores (medians over frames): best box on an obstacle %.3f, best box on "
                "none %.3f; in %d of %zu frames a box on no obstacle scores above every box on "
                "one\n",
                Median(on_obstacle), Median(on_none), outranked, a.frames.size());
  std::string out = line;
  std::snprintf(line, sizeof line,
                "Pixel AP of the paper's map (BP+Fusion@4): served %.3f; boxes on no obstacle "
                "scored 0: %.3f; perfect regressors (F from mask IoU): %.3f\n",
                a.pixel_ap.served, a.pixel_ap.false_boxes_removed, a.pixel_ap.perfect_scores);
  return out + line;
}

}  // namespace

Result<LossAnalysis> AnalyseLosses(const ModelBundle& bundle, const LossAnalysisOptions& options) {
  auto selection = SelectFrames(options.data.Spec());
  if (!selection.ok()) return selection.status();
  const int n = static_cast<int>(selection->frames.size());
  std::vector<FrameResult> results(n);
  const ObstacleDetector detector(bundle, "analyse");  // one copy of the bundle for the run
  std::array<PixelHistogramAccumulator, kApScorings> pixels;
  std::mutex mutex;
  int done = 0;
  const std::vector<Status> per_frame = ParallelFor(n, options.threads, [&](int i) -> Status {
    auto sample = selection->dataset->Load(selection->frames[i]);
    if (!sample.ok()) return sample.status();
    Result<FrameResult> result = AnalyseFrame(detector, *sample, options);
    if (!result.ok()) return result.status();
    results[i] = std::move(result).value();
    std::lock_guard lock(mutex);
    // Pooled as `tod eval` pools BP+Fusion@4: obstacle pixels against free space.
    for (int k = 0; k < kApScorings; ++k) {
      if (Status st = pixels[k].Add(results[i].maps[k], sample->obstacle, sample->road); !st.ok())
        return st;
      results[i].maps[k].release();
    }
    ++done;
    if (options.progress && (done % 5 == 0 || done == n))
      options.progress("analysed " + std::to_string(done) + "/" + std::to_string(n) + " frames");
    return Status::Ok();
  });
  std::vector<SkippedFrame> skipped;
  const Status bad = ApplyBadFramePolicy(
      per_frame, [&](int i) { return selection->dataset->name(selection->frames[i]); },
      options.data.on_bad_frame, &skipped);
  if (!bad.ok()) return bad;
  LossAnalysis out;
  out.pixel_ap = {pixels[0].Ap(), pixels[1].Ap(), pixels[2].Ap()};
  for (int i = 0; i < n; ++i) {
    if (!per_frame[i].ok()) continue;
    out.frames.push_back(results[i].work);
    out.obstacles.insert(out.obstacles.end(), results[i].fates.begin(), results[i].fates.end());
  }
  return out;
}

std::string FormatLossAnalysis(const LossAnalysis& a, const LossAnalysisOptions& options) {
  struct Band {
    const char* name;
    int min_h, max_h;
  };
  const std::vector<Band> bands = {{"all", 0, 1 << 30},
                                   {"h < 20 px", 0, 19},
                                   {"h 20-49 px", 20, 49},
                                   {"h >= 50 px", 50, 1 << 30}};
  std::ostringstream o;
  char line[256];
  std::snprintf(line, sizeof line,
                "Where obstacles are lost (share found at box IoU >= %.2f; top %d)\n",
                options.hit_iou, options.top_n);
  o << line;
  std::snprintf(line, sizeof line, "%-12s %5s %8s %8s %9s %9s %9s %9s\n", "obstacles", "n",
                "E cont.", "OCC cont.", "any box", "filtered", "top obj", "top reg");
  o << line;
  for (const Band& b : bands) {
    int n = 0, any = 0, kept = 0, top = 0, reg = 0;
    double base = 0, occ = 0;
    for (const ObstacleFate& f : a.obstacles) {
      if (f.box.h < b.min_h || f.box.h > b.max_h) continue;
      ++n;
      base += f.contour_base_edges;
      occ += f.contour_occlusion;
      any += f.best_iou_unfiltered >= options.hit_iou;
      kept += f.best_iou_filtered >= options.hit_iou;
      top += f.proposal_rank >= 0;
      reg += f.regressed_rank >= 0;
    }
    const double d = std::max(1, n);
    std::snprintf(line, sizeof line, "%-12s %5d %8.2f %8.2f %9.2f %9.2f %9.2f %9.2f\n", b.name, n,
                  base / d, occ / d, any / d, kept / d, top / d, reg / d);
    o << line;
  }
  std::vector<double> base, occ, sp, windows, proposals;
  for (const FrameWork& w : a.frames) {
    base.push_back(w.base_edge_density);
    occ.push_back(w.occlusion_density);
    sp.push_back(w.superpixels);
    windows.push_back(static_cast<double>(w.windows_scored));
    proposals.push_back(static_cast<double>(w.proposals));
  }
  std::snprintf(line, sizeof line,
                "\nFrames %zu (medians): E > 0.1 on %.1f %% of R1, occlusion edges > 0.1 on %.1f "
                "%%, %.0f superpixels, %.2f M windows scored, %.0f proposals\n",
                a.frames.size(), 100 * Median(base), 100 * Median(occ), Median(sp),
                Median(windows) / 1e6, Median(proposals));
  o << line;
  o << FormatScoreComparison(a);
  return o.str();
}

nlohmann::json LossAnalysisToJson(const LossAnalysis& a) {
  nlohmann::json j;
  j["obstacles"] = nlohmann::json::array();
  for (const ObstacleFate& f : a.obstacles)
    j["obstacles"].push_back({{"frame", f.frame},
                              {"box", {f.box.x, f.box.y, f.box.w, f.box.h}},
                              {"pixels", f.pixels},
                              {"range", f.range},
                              {"in_r1", f.in_r1},
                              {"contour_base_edges", f.contour_base_edges},
                              {"contour_occlusion", f.contour_occlusion},
                              {"best_iou_unfiltered", f.best_iou_unfiltered},
                              {"best_iou_filtered", f.best_iou_filtered},
                              {"proposal_rank", f.proposal_rank},
                              {"regressed_rank", f.regressed_rank}});
  j["frames"] = nlohmann::json::array();
  for (const FrameWork& w : a.frames)
    j["frames"].push_back({{"frame", w.frame},
                           {"base_edge_density", w.base_edge_density},
                           {"occlusion_density", w.occlusion_density},
                           {"superpixels", w.superpixels},
                           {"windows_scored", w.windows_scored},
                           {"proposals", w.proposals},
                           {"best_obstacle_box_score", w.best_obstacle_box_score},
                           {"best_false_box_score", w.best_false_box_score},
                           {"false_boxes_above", w.false_boxes_above}});
  j["pixel_ap"] = {{"served", a.pixel_ap.served},
                   {"false_boxes_removed", a.pixel_ap.false_boxes_removed},
                   {"perfect_scores", a.pixel_ap.perfect_scores}};
  return j;
}

}  // namespace tod
