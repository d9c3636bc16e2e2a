#include "core/training/training_geometry.h"

#include <cstdio>
#include <optional>

#include "core/proposals/ground_plane_size_prior.h"

namespace tod::training {
namespace {

// The ground-plane size prior of the training obstacles, fitted on first use: the size filter
// and the ground-plane box features place the same horizon.
class GroundPlaneFit {
 public:
  explicit GroundPlaneFit(const std::vector<Box>& obstacle_boxes) : boxes_(obstacle_boxes) {}
  const Result<GroundPlaneSizePrior>& Get() {
    if (!fitted_) fitted_.emplace(FitGroundPlaneSizePrior(boxes_));
    return *fitted_;
  }

 private:
  const std::vector<Box>& boxes_;
  std::optional<Result<GroundPlaneSizePrior>> fitted_;
};

// The size filter of `--regions auto` bundles: the ground-plane prior (ours,
// docs/method.md#size-filter) or the authors' per-band extremes (§4.3). Recorded in
// parts["size_filter"].
Status DeriveSizeFilter(TrainingRun& run, const Survey& survey, GroundPlaneFit& ground_plane,
                        ModelBundle& bundle, nlohmann::json& parts) {
  if (run.options().size_filter_recipe == SizeFilterRecipe::kBands) {
    bundle.size_filter = SizeFilter::Derive(survey.obstacle_boxes);
    parts["size_filter"] = {{"recipe", EnumString(SizeFilterRecipe::kBands)},
                            {"obstacles", survey.obstacle_boxes.size()}};
    return Status::Ok();
  }
  const Result<GroundPlaneSizePrior>& prior = ground_plane.Get();
  if (!prior.ok())
    return prior.status().WithContext(
        "fitting the size filter's ground-plane prior (too few "
        "obstacles? --paper size_filter needs none)");
  bundle.size_filter = GroundPlaneSizeFilter(*prior, survey.obstacle_boxes);
  parts["size_filter"] = {{"recipe", EnumString(SizeFilterRecipe::kGroundPlane)},
                          {"obstacles", prior->obstacles},
                          {"horizon_y", prior->horizon_y},
                          {"h_per_row", {prior->h_ratio_min, prior->h_ratio_max}},
                          {"w_per_row", {prior->w_ratio_min, prior->w_ratio_max}},
                          {"area_per_row2", {prior->area_ratio_min, prior->area_ratio_max}}};
  char line[128];
  std::snprintf(line, sizeof line, "size filter: horizon at row %.1f, h/d %.3f-%.3f, w/d %.3f-%.3f",
                prior->horizon_y, prior->h_ratio_min, prior->h_ratio_max, prior->w_ratio_min,
                prior->w_ratio_max);
  run.Say(line);
  return Status::Ok();
}

// With ground-plane box features (PipelineParams::box_features), their horizon: the one the
// ground-plane size prior fits to the training obstacles, whatever the size filter's recipe.
Status PlaceFeatureHorizons(TrainingRun& run, GroundPlaneFit& ground_plane, ModelBundle& bundle,
                            nlohmann::json& parts) {
  // The occlusion classifier's sizes stay the paper's pixels (ground-plane ones were measured and
  // removed, docs/findings.md#occlusion-size-features); recorded as before, so the manifest reads
  // as older ones and a bundle that records ground-plane sizes is refused (removed_options.h).
  parts["occlusion_features"] = {{"size", "paper"}};
  GroundPlaneFeatureParams& params = bundle.params.box_features;
  params.ground_plane_size = run.options().box_size_features == BoxSizeFeatures::kGroundPlane;
  if (!params.ground_plane_size) {
    parts["box_features"] = {{"size", EnumString(BoxSizeFeatures::kPaper)}};
    return Status::Ok();
  }
  const Result<GroundPlaneSizePrior>& prior = ground_plane.Get();
  if (!prior.ok())
    return prior.status().WithContext(
        "placing the horizon of the ground-plane box_features (too few obstacles? --paper "
        "box_size_features needs none)");
  params.horizon_y = prior->horizon_y;
  parts["box_features"] = {{"size", EnumString(BoxSizeFeatures::kGroundPlane)},
                           {"horizon_y", params.horizon_y}};
  char line[64];
  std::snprintf(line, sizeof line, ": sizes over the rows below row %.1f", params.horizon_y);
  run.Say(std::string("box_features") + line);
  return Status::Ok();
}

// The training camera's horizon as the estimator sees it (self-calibration moves other cameras'
// frames against it). Too few frames with an estimate leave the bundle without one, said in the
// log and in every detection's horizon.fallback.
void MeasureHorizonReference(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                             nlohmann::json& parts) {
  Result<HorizonReference> reference = ReferenceFromEstimates(survey.horizons, survey.height);
  if (!reference.ok()) {
    run.Say("no horizon reference: " + reference.status().message());
    parts["horizon_reference"] = {{"error", reference.status().message()}};
    return;
  }
  bundle.horizon_reference = *reference;
  parts["horizon_reference"] = reference->ToJson();
  char line[128];
  std::snprintf(line, sizeof line, "horizon reference: row %.1f (spread %.1f) over %d frames",
                reference->row, reference->spread, reference->frames);
  run.Say(line);
}

}  // namespace

// Multilayer regions and the size filter from the training obstacles (§1.4, §4.3).
Status DeriveGeometry(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                      nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  GroundPlaneFit ground_plane(survey.obstacle_boxes);
  if (options.regions == RegionsSource::kLaf2020) {
    bundle.regions = Laf2020Regions().ScaledTo(survey.width, survey.height);
    bundle.size_filter = SizeFilter::Laf2020();
    parts["size_filter"] = {{"recipe", EnumString(RegionsSource::kLaf2020)}};
    if (survey.width != 2048 || survey.height != 1024) {
      if (Status st = DeriveSizeFilter(run, survey, ground_plane, bundle, parts); !st.ok())
        return st;
    }
  } else {
    RegionParams region_params = options.params.regions;
    region_params.seed = options.seed;
    auto regions =
        DeriveMultilayerRegions(survey.footprints, survey.width, survey.height, region_params);
    if (!regions.ok()) return regions.status().WithContext("deriving the multilayer regions");
    bundle.regions = *regions;
    if (Status st = DeriveSizeFilter(run, survey, ground_plane, bundle, parts); !st.ok()) return st;
  }
  bundle.size_filter.enabled = options.params.size_filter;
  if (Status st = PlaceFeatureHorizons(run, ground_plane, bundle, parts); !st.ok()) return st;
  MeasureHorizonReference(run, survey, bundle, parts);
  for (int k = 0; k < bundle.regions.num_layers(); ++k) {
    const Box& r = bundle.regions.layers[k];
    char line[96];  // snprintf: GCC 12 warns (-Wrestrict, falsely) on "R" + std::to_string
    std::snprintf(line, sizeof line, "R%d = [%d, %d, %d x %d]", k + 1, r.x, r.y, r.w, r.h);
    run.Say(line);
  }
  return Status::Ok();
}

}  // namespace tod::training
