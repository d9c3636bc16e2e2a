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
#include "core/pipeline/proposal_features.h"
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

// The occlusion classifier's features on the crop `oaocc` holds: the frame's options
// (OcclusionFeatureOptionsForFrame) with crop_y at R1's first row. ComputeOcclusionEdges paints
// with these, and the trainer samples with them.
OcclusionFeatureOptions OcclusionFeaturesOnCrop(OcclusionFeatureOptions frame_options,
                                                const OcclusionEdges& oaocc);

// enhance = false gives the plain (non obstacle-aware) variant used by the OLP baseline.
// With a null classifier only E, Ê and the superpixels are computed (training of the classifier).
// `occlusion_features` are the classifier's (OcclusionFeatureOptionsForFrame; crop_y is set here,
// OcclusionFeaturesOnCrop).
// When the timer asks to stop at a stage boundary the maps computed so far are returned and the
// caller reads timer->stopped(); a stage that rejects its input is an error naming the stage.
// With a frame budget the occlusion classifier walks its trees until the budget's
// OcclusionDeadline (asked when the stage starts).
Result<OcclusionEdges> ComputeOcclusionEdges(
    const cv::Mat3b& image, const MultilayerRegions& regions, const EdgeSource& edges,
    const OcclusionClassifier* classifier, const OcclusionFeatureOptions& occlusion_features,
    const PipelineParams& params, bool enhance, StageTimer* timer = nullptr,
    const FrameBudget* budget = nullptr);

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
  std::vector<ScoredBox> boxes;  // full-image coordinates, objectness descending
  std::vector<int> layer;        // 0-based region that produced each box
  // Regions (0-based) whose window scan the deadline cut short.
  std::vector<int> truncated_regions;
};

// Region k's (0-based) window-scan parameters: box_params with the multistride factor
// (K - k + 1) / K of §4.2.6 (paper index k + 1), or 1 without multistride.
EdgeBoxParams RegionBoxParams(const EdgeBoxParams& box_params, int k, int num_layers,
                              bool multistride);

// Boxes of region k (0-based) in full-image coordinates, objectness descending, through the size
// filter when one is given. `stats` (may be null) receives the scorer's counters for the region
// (boxes_out counts the boxes before the size filter's final pass).
std::vector<ScoredBox> ProposeRegionBoxes(const OcclusionEdges& oaocc,
                                          const MultilayerRegions& regions,
                                          const EdgeBoxParams& box_params, int k, bool multistride,
                                          const SizeFilter* size_filter,
                                          EdgeBoxStats* stats = nullptr);
// The union of per-region boxes (index = region), ranked by objectness, through a greedy NMS at
// merge_iou across regions (1 = the plain union, as the authors' code); ties keep region order.
ProposalSet MergeRegionBoxes(const std::vector<std::vector<ScoredBox>>& per_region,
                             float merge_iou);

ProposalSet ProposeBoxes(const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                         const EdgeBoxParams& box_params, const ProposalOptions& options,
                         const SizeFilter& size_filter);

}  // namespace tod
