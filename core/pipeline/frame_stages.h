// The per-frame stages shared by detection, training and evaluation: obstacle-aware occlusion
// edges on R1 (§2-3), multistride proposals over the K regions (§4), the 20 features (§5).
#pragma once

#include <chrono>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/stage_timer.h"
#include "core/edges/edge_source.h"
#include "core/edges/occlusion_classifier.h"
#include "core/edges/sticky_superpixels.h"
#include "core/pipeline/frame_budget.h"
#include "core/pipeline/multilayer_regions.h"
#include "core/pipeline/pipeline_params.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/size_filter.h"
#include "core/proposals/window_admission.h"

namespace tod {

struct OcclusionEdges {
  Box r1;               // full-image box of the crop
  cv::Mat3b crop;       // image restricted to R1 (a view into the frame)
  cv::Mat1f base_edge;  // E
  cv::Mat1f enhanced;   // Ê = n(p) E(p)
  Superpixels superpixels;
  cv::Mat1f occlusion;  // occlusion edge map on the crop
  // Trees of the occlusion classifier walked for every pair: fewer than it has when the frame
  // budget cut the stage short (occlusion_cut_short).
  int occlusion_trees = 0;
  bool occlusion_cut_short = false;
};

// enhance = false gives the plain (non obstacle-aware) variant used by the OLP baseline.
// With a null classifier only E, Ê and the superpixels are computed (training of the classifier).
// When the timer asks to stop at a stage boundary the maps computed so far are returned and the
// caller reads timer->stopped(); a stage that rejects its input is an error naming the stage.
// With a frame budget the occlusion classifier walks its trees until the budget's
// OcclusionDeadline (asked when the stage starts).
Result<OcclusionEdges> ComputeOcclusionEdges(
    const cv::Mat3b& image, const MultilayerRegions& regions, const EdgeSource& edges,
    const OcclusionClassifier* classifier, const PipelineParams& params, bool enhance,
    StageTimer* timer = nullptr, const FrameBudget* budget = nullptr);

// Region k's occlusion edge map (un-normalised): the R1 map cropped to R_k, with the artificial
// frame edges along the crop border removed for k >= 2 (§3.2(4)). k is 0-based here.
cv::Mat1f RegionEdgeMap(const OcclusionEdges& oaocc, const MultilayerRegions& regions, int k);

struct ProposalOptions {
  int layers_used = 4;  // @k: boxes from R_1 .. R_k
  bool multistride = true;
  bool size_filter = true;
  float merge_iou = 0.75f;  // PipelineParams::region_merge_iou
  // Frame budget (frame_budget.h): the regions are scanned near to far, each until its share of
  // the time left to this deadline, by grid windows. No deadline: every window is scanned.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  // Threads of the stage (0 = all cores, for one region at a time). Above 1, up to that many
  // regions are scanned side by side, each with that many threads; the boxes are the same for
  // every count.
  int threads = 1;
};

// The detector's proposal options for a bundle's parameters: all `layers`, its multistride, size
// filter and cross-region merge settings.
ProposalOptions DetectorProposalOptions(const PipelineParams& params, int layers);

struct ProposalSet {
  // Full-image coordinates, in the merge's order (MergeRegionBoxes): each box's score is its own
  // region's Edge Boxes score.
  std::vector<ScoredBox> boxes;
  std::vector<int> layer;  // 0-based region that produced each box
  // Per region: the factor that puts its scores on the scale of the region whose map peaks
  // highest (its map's maximum over the largest; 1 when no map has an edge). Empty: all 1.
  std::vector<float> layer_scale;
  // Regions (0-based) whose window scan the deadline cut short.
  std::vector<int> truncated_regions;
};

// Region k's (0-based) window-scan parameters: box_params with the multistride factor
// (K - k + 1) / K of §4.2.6 (paper index k + 1), or 1 without multistride.
EdgeBoxParams RegionBoxParams(const EdgeBoxParams& box_params, int k, int num_layers,
                              bool multistride);

// One region's proposals. Edge Boxes scores a region on its map divided by the map's maximum
// (§4.2), so a box's score is in units of its own region's `edge_max`.
struct RegionProposals {
  std::vector<ScoredBox> boxes;  // full-image coordinates, objectness descending
  float edge_max = 0.f;          // largest value of the region's occlusion-edge map
};

// Boxes of region k (0-based) in full-image coordinates, objectness descending, through the size
// filter when one is given. `stats` (may be null) receives the scorer's counters for the region
// (boxes_out counts the boxes before the size filter's final pass).
RegionProposals ProposeRegionBoxes(const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                                   const EdgeBoxParams& box_params, int k, bool multistride,
                                   const SizeFilter* size_filter, EdgeBoxStats* stats = nullptr);
// The union of per-region boxes (index = region), ordered by their regions' scores (ties keep
// region order), through a greedy NMS at merge_iou across regions (1 = the plain union, as the
// authors' code). Of a window found by several regions, NMS thus keeps the copy of the region
// where it stands out most against that region's peak, usually the innermost: its features
// come from the map the paper made that region for. Sets layer_scale from the regions' edge_max.
ProposalSet MergeRegionBoxes(const std::vector<RegionProposals>& per_region, float merge_iou);

// The proposals' boxes ranked by objectness on one scale across regions (score times its
// region's layer_scale), ties in list order: the ranking average recall reads. The regions'
// own scores are in units of their own maps' maxima, so ranked as they are, a region whose map
// peaks lower put its boxes above the same windows found by the regions around it.
std::vector<Box> RankedOnCommonScale(const ProposalSet& proposals);

// Every used region's boxes (ProposeRegionBoxes), before the merge: up to options.threads regions
// side by side, each scanned with that many threads; the same boxes for any count.
struct FrameRegionProposals {
  std::vector<RegionProposals> per_region;  // index = region
  std::vector<int> truncated_regions;       // as ProposalSet's
  std::vector<EdgeBoxStats> stats;          // index = region: its scan's counters
};
FrameRegionProposals ProposeRegions(const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                                    const EdgeBoxParams& box_params, const ProposalOptions& options,
                                    const SizeFilter& size_filter);

// MergeRegionBoxes of the frame's regions, with their truncated_regions.
ProposalSet MergeFrameRegions(const FrameRegionProposals& found, float merge_iou);

// ProposeRegions, then MergeFrameRegions.
ProposalSet ProposeBoxes(const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                         const EdgeBoxParams& box_params, const ProposalOptions& options,
                         const SizeFilter& size_filter);

}  // namespace tod
