#include "server/detect_response.h"

namespace tod::server {
namespace {

void FillBox(const Box& box, tod::v1::Box* out) {
  out->set_x(box.x);
  out->set_y(box.y);
  out->set_w(box.w);
  out->set_h(box.h);
}

}  // namespace

RequestOptions OptionsFromProto(const tod::v1::DetectOptions& options) {
  RequestOptions out;
  if (options.has_max_proposals()) out.detect.max_proposals = options.max_proposals();
  if (options.has_obstacle_threshold()) {
    out.detect.obstacle_threshold = options.obstacle_threshold();
  }
  if (options.has_min_obstacle_score()) {
    out.detect.min_obstacle_score = options.min_obstacle_score();
  }
  if (options.has_budget_ms()) out.detect.budget_ms = options.budget_ms();
  if (options.has_calibrate()) out.detect.calibrate = options.calibrate();
  out.detect.map_kind = options.map_kind() == tod::v1::MAP_KIND_CALIBRATED ? MapKind::kCalibrated
                                                                           : MapKind::kNormalized;
  out.encode_map_png = options.map_format() != tod::v1::MAP_FORMAT_NONE;
  out.detect.want_probability_map = out.encode_map_png;
  return out;
}

void FillDetectResponse(const InferenceResult& result, const std::string& frame_id,
                        tod::v1::DetectResponse* response) {
  const Detection& detection = result.detection;
  response->set_frame_id(frame_id);
  if (result.model) response->set_model_version(result.model->detector->info().version);
  response->set_width(detection.width);
  response->set_height(detection.height);
  for (const DetectedObstacle& obstacle : detection.obstacles) {
    tod::v1::Obstacle* out = response->add_obstacles();
    FillBox(obstacle.box, out->mutable_box());
    out->set_area(static_cast<int32_t>(obstacle.area));
    out->set_peak_probability(obstacle.peak_probability);
    out->set_mean_probability(obstacle.mean_probability);
    out->set_score(obstacle.score);
    out->set_evidence(obstacle.evidence);
  }
  for (const Proposal& proposal : detection.proposals) {
    tod::v1::Proposal* out = response->add_proposals();
    FillBox(proposal.box, out->mutable_box());
    out->set_fused(proposal.fused);
    out->set_ordr(proposal.ordr);
    out->set_obdr(proposal.obdr);
  }
  if (!result.map_png.empty()) {
    tod::v1::ProbabilityMap* map = response->mutable_probability_map();
    map->set_width(detection.probability.cols);
    map->set_height(detection.probability.rows);
    map->set_png(result.map_png);
    map->set_kind(detection.map_kind == MapKind::kCalibrated ? tod::v1::MAP_KIND_CALIBRATED
                                                             : tod::v1::MAP_KIND_NORMALIZED);
  }
  for (const auto& [stage, ms] : result.timings) {
    tod::v1::StageTiming* timing = response->add_timings();
    timing->set_stage(stage);
    timing->set_ms(ms);
  }
  response->set_total_ms(result.total_ms);
  response->set_degraded(detection.degraded());
  for (const std::string& stage : detection.degraded_stages) response->add_degraded_stages(stage);
  FillGeometry(detection, response->mutable_geometry());
}

void FillGeometry(const Detection& detection, tod::v1::Geometry* geometry) {
  const HorizonUse& h = detection.horizon;
  geometry->set_source(HorizonSourceName(h.source));
  if (h.row) geometry->set_horizon_row(*h.row);
  if (h.bundle_row) geometry->set_bundle_horizon_row(*h.bundle_row);
  if (h.frame_estimate) geometry->set_frame_horizon_row(*h.frame_estimate);
  geometry->set_camera_frames(h.camera_frames);
  geometry->set_shift_rows(h.shift);
  const Box& r = detection.road_region;
  tod::v1::Box* road = geometry->mutable_road_region();
  road->set_x(r.x), road->set_y(r.y), road->set_w(r.w), road->set_h(r.h);
  geometry->set_fallback(h.fallback);
}

void FillModelInfo(const LoadedModel& model, tod::v1::ModelInfo* info) {
  const ModelInfo& bundle = model.detector->info();
  info->set_name(bundle.name);
  info->set_version(bundle.version);
  info->set_format_version(bundle.format_version);
  info->set_created(bundle.created);
  info->set_trained_on(bundle.trained_on);
  info->set_edge_source(bundle.edge_source);
  info->set_manifest_json(bundle.manifest.dump());
  // The bundle's name only: the server's filesystem layout is nobody's business on the wire.
  info->set_model_dir(bundle.name);
  info->set_generation(model.generation);
  info->set_loaded_at(model.loaded_at);
}

}  // namespace tod::server
