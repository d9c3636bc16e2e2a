#include "core/training/training_geometry.h"

#include <cstdio>
#include <optional>

#include "core/proposals/ground_plane_size_prior.h"

namespace tod::training {
namespace {

// The ground-plane size prior of the training obstacles, fitted on first use: the size filter
// and both kinds of ground-plane features place the same horizon.
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
  const std::string& recipe = run.options().size_filter_recipe;
  if (recipe == "bands") {
    bundle.size_filter = SizeFilter::Derive(survey.obstacle_boxes);
    parts["size_filter"] = {{"recipe", "bands"}, {"obstacles", survey.obstacle_boxes.size()}};
    return Status::Ok();
  }
  if (recipe != "ground_plane")
    return Status::InvalidArgument("--size-filter-recipe must be ground_plane or bands, got '" +
                                   recipe + "'");
  const Result<GroundPlaneSizePrior>& prior = ground_plane.Get();
  if (!prior.ok())
    return prior.status().WithContext(
        "fitting the size filter's ground-plane prior (too few "
        "obstacles? --size-filter-recipe bands needs none)");
  bundle.size_filter = GroundPlaneSizeFilter(*prior, survey.obstacle_boxes);
  parts["size_filter"] = {{"recipe", "ground_plane"},
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

// With ground-plane sizes (PipelineParams::box_features, occlusion_features), their horizon: the
// one the ground-plane size prior fits to the training obstacles, whatever the size filter's
// recipe. `choice` is the option's value, `flag` its name, `part` the manifest key.
Status PlaceGroundPlaneHorizon(TrainingRun& run, GroundPlaneFit& ground_plane,
                               const std::string& choice, const std::string& flag,
                               const std::string& part, GroundPlaneFeatureParams& params,
                               nlohmann::json& parts) {
  if (choice != "ground_plane" && choice != "paper")
    return Status::InvalidArgument(flag + " must be ground_plane or paper, got '" + choice + "'");
  params.ground_plane_size = choice == "ground_plane";
  if (!params.ground_plane_size) {
    parts[part] = {{"size", "paper"}};
    return Status::Ok();
  }
  const Result<GroundPlaneSizePrior>& prior = ground_plane.Get();
  if (!prior.ok())
    return prior.status().WithContext("placing the horizon of the ground-plane " + part +
                                      " (too few obstacles? " + flag + " paper needs none)");
  params.horizon_y = prior->horizon_y;
  parts[part] = {{"size", "ground_plane"}, {"horizon_y", params.horizon_y}};
  char line[64];
  std::snprintf(line, sizeof line, ": sizes over the rows below row %.1f", params.horizon_y);
  run.Say(part + line);
  return Status::Ok();
}

Status PlaceFeatureHorizons(TrainingRun& run, GroundPlaneFit& ground_plane, ModelBundle& bundle,
                            nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  if (Status st = PlaceGroundPlaneHorizon(run, ground_plane, options.box_size_features,
                                          "--box-size-features", "box_features",
                                          bundle.params.box_features, parts);
      !st.ok())
    return st;
  return PlaceGroundPlaneHorizon(run, ground_plane, options.occlusion_size_features,
                                 "--occlusion-size-features", "occlusion_features",
                                 bundle.params.occlusion_features, parts);
}

}  // namespace

// Multilayer regions and the size filter from the training obstacles (§1.4, §4.3).
Status DeriveGeometry(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                      nlohmann::json& parts) {
  const TrainOptions& options = run.options();
  GroundPlaneFit ground_plane(survey.obstacle_boxes);
  if (options.regions == "laf2020") {
    bundle.regions = Laf2020Regions().ScaledTo(survey.width, survey.height);
    bundle.size_filter = SizeFilter::Laf2020();
    parts["size_filter"] = {{"recipe", "laf2020"}};
    if (survey.width != 2048 || survey.height != 1024) {
      if (Status st = DeriveSizeFilter(run, survey, ground_plane, bundle, parts); !st.ok())
        return st;
    }
  } else if (options.regions == "auto") {
    RegionParams region_params = options.params.regions;
    region_params.seed = options.seed;
    auto regions =
        DeriveMultilayerRegions(survey.footprints, survey.width, survey.height, region_params);
    if (!regions.ok()) return regions.status().WithContext("deriving the multilayer regions");
    bundle.regions = *regions;
    if (Status st = DeriveSizeFilter(run, survey, ground_plane, bundle, parts); !st.ok()) return st;
  } else {
    return Status::InvalidArgument("--regions must be auto or laf2020, got '" + options.regions +
                                   "'");
  }
  bundle.size_filter.enabled = options.params.size_filter;
  if (Status st = PlaceFeatureHorizons(run, ground_plane, bundle, parts); !st.ok()) return st;
  for (int k = 0; k < bundle.regions.num_layers(); ++k) {
    const Box& r = bundle.regions.layers[k];
    char line[96];  // snprintf: GCC 12 warns (-Wrestrict, falsely) on "R" + std::to_string
    std::snprintf(line, sizeof line, "R%d = [%d, %d, %d x %d]", k + 1, r.x, r.y, r.w, r.h);
    run.Say(line);
  }
  return Status::Ok();
}

}  // namespace tod::training
