#include "core/pipeline/pipeline_params.h"

#include <cmath>
#include <string>

#include "core/features/box_features.h"
#include "core/pipeline/json_integers.h"
#include "core/pipeline/removed_options.h"

namespace tod {

// Field lists for nlohmann's (de)serialisers: missing keys keep the paper's defaults, wrong types
// throw and are reported below. EdgeBoxParams::threads is a run-time choice, not a model
// parameter, so it is not stored.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RegionParams, num_layers, restarts, max_iterations,
                                                margin_fraction, seed)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(GradientEdgeParams, smooth_radius,
                                                normalise_percentile)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(StickySuperpixelParams, k, alpha, beta, iterations)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(EdgeBoxParams, alpha, beta, min_score, max_boxes,
                                                edge_min_mag, edge_merge_thr, cluster_min_mag,
                                                max_aspect_ratio, max_wide_aspect_ratio,
                                                min_box_area, gamma, kappa, min_stride, refine,
                                                refine_limit, refine_local_maxima)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(FusionParams, beta1, keep_ratio)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(BoxIsolationParams, exponent, context_boxes,
                                                surround)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ProbabilityMapParams, min_score, nms_iou, max_boxes,
                                                top_fraction, isolation, superpixel_shares)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(PriorCorrection, edge_odds, occlusion_odds)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ForestScreening, trees, final_at_most)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ObstacleCalibration, fitted, slope, intercept,
                                                samples, positives, flat)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(GroundPlaneFeatureParams, ground_plane_size,
                                                horizon_y)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(PipelineParams, regions, gradient_edges,
                                                superpixels, boxes, multistride, size_filter,
                                                region_merge_iou, prior_correction,
                                                occlusion_screening, obstacle_calibration, fusion,
                                                probability_map, box_features,
                                                vertical_edge_feature, road_surround_feature)

nlohmann::json ToJson(const PipelineParams& params) {
  nlohmann::json j = params;
  WriteRemovedParams(j);
  return j;
}

void CorrectSampledPrior(cv::Mat1f& probability, double odds_scale) {
  if (odds_scale == 1.0) return;
  const float c = static_cast<float>(odds_scale);
  probability.forEach([c](float& p, const int*) {
    if (p > 0.f && p < 1.f) p = p * c / (p * c + (1.f - p));
  });
}

Result<PipelineParams> PipelineParamsFromJson(const nlohmann::json& j) {
  // The readers above cast any number to an int field (json_integers.h): check those first.
  if (Status s = CheckJsonIntegers(j, ToJson(PipelineParams{}), "parameters: "); !s.ok()) return s;
  PipelineParams p;
  try {
    p = j.get<PipelineParams>();
  } catch (const nlohmann::json::exception& e) {
    return Status::InvalidArgument(std::string("parameters: ") + e.what());
  }
  const Status boxes = ValidateEdgeBoxParams(p.boxes);
  if (!boxes.ok()) return Status::InvalidArgument("parameters: " + boxes.message());
  const ObstacleCalibration& calibration = p.obstacle_calibration;
  if (calibration.fitted && !(calibration.slope >= 0 && std::isfinite(calibration.slope) &&
                              std::isfinite(calibration.intercept)))
    return Status::InvalidArgument(
        "parameters: obstacle_calibration.slope must be finite and >= 0 (a negative slope makes "
        "an obstacle's score fall as its evidence rises; retrain the bundle), got " +
        std::to_string(calibration.slope));
  if (p.regions.num_layers < 1 || p.superpixels.k < 1 || p.fusion.keep_ratio < 0 ||
      p.fusion.keep_ratio > 1 || p.probability_map.top_fraction < 0 ||
      p.probability_map.top_fraction > 1 || !(p.region_merge_iou > 0 && p.region_merge_iou <= 1) ||
      !(p.probability_map.isolation.exponent >= 0 &&
        std::isfinite(p.probability_map.isolation.exponent)) ||
      p.probability_map.isolation.context_boxes < 1 ||
      !(p.probability_map.isolation.surround >= 1 &&
        std::isfinite(p.probability_map.isolation.surround)) ||
      !(p.prior_correction.edge_odds > 0) || !(p.prior_correction.occlusion_odds > 0) ||
      p.occlusion_screening.trees < 0 ||
      !(p.occlusion_screening.final_at_most >= 0 && p.occlusion_screening.final_at_most < 1) ||
      !std::isfinite(p.box_features.horizon_y))
    return Status::InvalidArgument(
        "parameters out of range (regions.num_layers, superpixels.k, fusion.keep_ratio, "
        "probability_map.top_fraction, region_merge_iou in (0, 1], prior_correction > 0, "
        "probability_map.isolation: exponent >= 0, context_boxes >= 1, surround >= 1, "
        "occlusion_screening: trees >= 0, final_at_most in [0, 1), box_features.horizon_y "
        "finite)");
  return p;
}

int ProposalFeatureCount(const PipelineParams& params) {
  BoxFeatureOptions options;
  options.vertical_edges = params.vertical_edge_feature;
  options.road_surround = params.road_surround_feature;
  return NumBoxFeatures(options);
}

std::string ProposalFeatureSet(const PipelineParams& params) {
  std::string set = "the paper's 20";
  if (params.vertical_edge_feature) set += ", the vertical edge share";
  if (params.road_surround_feature) set += ", the surround unlike the road";
  return set;
}

PipelineParams TrainingDefaultParams() {
  PipelineParams params;
  params.occlusion_screening = {.trees = 25, .final_at_most = 0.05f};
  params.probability_map.superpixel_shares = true;
  params.vertical_edge_feature = true;
  params.road_surround_feature = true;
  params.boxes.max_wide_aspect_ratio = 10.f;
  return params;
}

}  // namespace tod
