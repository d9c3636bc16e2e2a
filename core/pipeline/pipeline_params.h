// Every parameter of the pipeline in one struct, with the paper's defaults (ALGORITHM.md). The
// bundle's manifest stores it, so a model always runs with what it was trained with.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "core/base/status.h"
#include "core/edges/edge_source.h"
#include "core/edges/occlusion_classifier.h"
#include "core/edges/sticky_superpixels.h"
#include "core/pipeline/multilayer_regions.h"
#include "core/pipeline/obstacle_calibration.h"
#include "core/pipeline/probability_map.h"
#include "core/proposals/edge_box_scorer.h"

namespace tod {

// The edge and occlusion classifiers are trained on class-balanced samples (every obstacle
// contour, a few negatives per positive), so their raw outputs carry the balanced prior: on a
// real frame, where obstacle contours are a tiny share of all boundaries, nearly every texture
// boundary scores above Edge Boxes' 0.1 (docs/method.md#prior-correction). The correction for
// class-dependent sampling maps p to p·c / (p·c + 1 - p) with c = (rate at which negatives were
// kept) / (rate at which positives were kept), measured by `tod train`; 1 = uncorrected (bundles
// made before the correction).
struct PriorCorrection {
  double edge_odds = 1.0;       // c of the pixel edge classifier
  double occlusion_odds = 1.0;  // c of the occlusion classifier
};

// Sizes measured on the ground plane (ours; docs/method.md#ground-plane-box-features). With few
// training frames the learned parts see obstacles at a few distances only, and a size in pixels
// then says "as far as the training obstacles stood": a near obstacle, larger than any they saw,
// looks like the large patches of road and background. On a flat road image lengths are
// physical lengths times the distance below the horizon (the ground-plane size prior fits that
// horizon), so with ground_plane_size a length is divided by d = row − horizon_y (at least 1 px)
// and an area by d². horizon_y is in the training frame's pixels (frame_geometry.h maps it to
// other frame sizes). Off: the paper's pixel sizes. Used by box_features: proposal features 10, 12
// and 13 (§5: centre column, width and height over the image's) become (centre column − middle
// column) / d, w / d and h / d, d from the box's centre row: a lateral position and a size that
// every training obstacle informs.
struct GroundPlaneFeatureParams {
  bool ground_plane_size = false;
  double horizon_y = 0.0;
};

// p -> p·c / (p·c + 1 - p) on every pixel in place (0 stays 0, 1 stays 1; c = 1: unchanged).
void CorrectSampledPrior(cv::Mat1f& probability, double odds_scale);

struct PipelineParams {
  RegionParams regions;
  GradientEdgeParams gradient_edges;
  StickySuperpixelParams superpixels;
  // The paper's Edge Boxes parameters, except that refinement is narrowed to the 5000 best grid
  // local maxima per region: refining every scoring window does not fit the frame budget
  // (docs/method.md#local-maxima-refinement; `tod train --paper local_maxima_refinement` restores
  // the paper's).
  EdgeBoxParams boxes = [] {
    EdgeBoxParams p;
    p.refine_local_maxima = true;
    p.refine_limit = 5000;
    return p;
  }();
  bool multistride = true;  // MS: stride factor (K - k + 1) / K in region k (§4.2.6)
  bool size_filter = true;  // §4.3, switchable
  // NMS IoU across regions when their boxes are merged into one ranking (ours; the authors' code
  // merges without it, = 1). R2..RK are crops of the same occlusion map as R1, so without it the
  // inner regions add near-copies of R1's best boxes, which take the top ranks from distinct
  // boxes: on real frames more layers then *lowered* recall (docs/method.md#cross-region-nms).
  float region_merge_iou = 0.75f;
  PriorCorrection prior_correction;
  // Early exit in the occlusion classifier (ours; OcclusionPaintOptions): a superpixel pair
  // whose mean over the first `trees` trees is at most `final_at_most` keeps it. {0, 0} (every
  // tree on every pair, the reference) here, so a bundle whose manifest predates it keeps its
  // maps; `tod train` writes {25, 0.05} (TrainingDefaultParams).
  ForestScreening occlusion_screening;
  ObstacleCalibration obstacle_calibration;  // fitted by `tod train`
  FusionParams fusion;
  ProbabilityMapParams probability_map;
  GroundPlaneFeatureParams box_features;
  // Proposal feature 21, the share of a box's strong gradient on near-vertical edges (ours;
  // vertical_edges.h, docs/method.md#vertical-edge-feature). false, the default and the paper's 20
  // features, so a bundle whose manifest predates it keeps its regressors' rows; `tod train`
  // turns it on (TrainingDefaultParams).
  bool vertical_edge_feature = false;
  // One more proposal feature after those: how unlike the road just in front of the car a box's
  // surround is (ours; box_features.h, docs/method.md#road-surround-feature). false, the default,
  // so a bundle whose manifest predates it keeps its regressors' rows; `tod train` turns it on
  // (TrainingDefaultParams).
  bool road_surround_feature = false;
};

// The proposal features the regressors of a bundle with these parameters read: how many (20 to
// 22; box_features.h's NumBoxFeatures) and which, in words.
int ProposalFeatureCount(const PipelineParams& params);
std::string ProposalFeatureSet(const PipelineParams& params);

// The parameters `tod train` gives a new bundle: the defaults above, with the occlusion
// classifier's early exit at {25 trees, 0.05}. A pair whose first 25 of 400 trees average at
// most 0.05 (about three quarters of a real frame's 17 k pairs) keeps that mean. Such a pair
// ends at most about 0.2 over the whole forest, which the prior correction maps under a
// hundredth of a frame's strongest boundary, far below the tenth of a region's maximum that
// the proposals take as an edge. Both dev folds x four forest seeds: every proposal and pixel
// metric within 0.01 of the whole walk (TPR@FPR 0.02 0.801 -> 0.816), for about 40 % of the
// occlusion stage (docs/method.md#occlusion-early-exit). The bound 0.1 cost AP 0.015 and was not
// taken. And the map weighs its boxes by superpixel shares (ProbabilityMapParams;
// docs/method.md#superpixel-shares), and the proposals have the vertical edge share as a 21st
// feature (docs/method.md#vertical-edge-feature).
PipelineParams TrainingDefaultParams();

// Also writes the keys of removed parameters at their one remaining value (removed_options.h),
// so a manifest reads as those written before their removal.
nlohmann::json ToJson(const PipelineParams& params);
// Missing keys keep their defaults; wrong types are an error naming the key. The keys of removed
// parameters are not read here (RefuseRemovedOptions checks them at load).
Result<PipelineParams> PipelineParamsFromJson(const nlohmann::json& j);

}  // namespace tod
