#include "server/metrics.h"

#include <prometheus/text_serializer.h>

#include "core/calibration/horizon_choice.h"
#include "server/core/cancellation.h"

namespace tod::server {
namespace {

// Seconds; spans a fast small frame (ms) to a full-size frame of the paper's pipeline (~10 s).
prometheus::Histogram::BucketBoundaries LatencyBuckets() {
  return {0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30};
}

}  // namespace

ServerMetrics::ServerMetrics()
    : registry_(std::make_shared<prometheus::Registry>()),
      requests_(prometheus::BuildCounter()
                    .Name("tod_requests_total")
                    .Help("Finished requests by protocol and gRPC status code")
                    .Register(*registry_)),
      request_duration_(prometheus::BuildHistogram()
                            .Name("tod_request_duration_seconds")
                            .Help("Admission to response, by protocol")
                            .Register(*registry_)),
      queue_duration_(prometheus::BuildHistogram()
                          .Name("tod_queue_duration_seconds")
                          .Help("Time a request waited in the queue for a worker")
                          .Register(*registry_)
                          .Add({}, LatencyBuckets())),
      stage_duration_(prometheus::BuildHistogram()
                          .Name("tod_stage_duration_seconds")
                          .Help("Per-stage processing time (decode, pipeline stages, encode)")
                          .Register(*registry_)),
      queue_depth_(prometheus::BuildGauge()
                       .Name("tod_queue_depth")
                       .Help("Requests waiting for a worker")
                       .Register(*registry_)
                       .Add({})),
      in_flight_(prometheus::BuildGauge()
                     .Name("tod_in_flight_requests")
                     .Help("Requests admitted and not yet answered (queued or running)")
                     .Register(*registry_)
                     .Add({})),
      rejections_(prometheus::BuildCounter()
                      .Name("tod_rejections_total")
                      .Help("Requests refused, by reason")
                      .Register(*registry_)),
      cancelled_(prometheus::BuildCounter()
                     .Name("tod_requests_cancelled_total")
                     .Help("Requests whose work was stopped at a stage boundary or skipped in "
                           "the queue, by reason")
                     .Register(*registry_)),
      degraded_(prometheus::BuildCounter()
                    .Name("tod_frames_degraded_total")
                    .Help("Requests whose frame budget cut a stage short, by stage")
                    .Register(*registry_)),
      http_refused_(prometheus::BuildCounter()
                        .Name("tod_http_refused_total")
                        .Help("Requests or connections the HTTP front end refused, by reason")
                        .Register(*registry_)),
      http_connections_(prometheus::BuildGauge()
                            .Name("tod_http_open_connections")
                            .Help("Open REST connections")
                            .Register(*registry_)
                            .Add({})),
      model_info_(prometheus::BuildGauge()
                      .Name("tod_model_info")
                      .Help("The models serving (value 1), labelled with name, version, generation")
                      .Register(*registry_)),
      reloads_(prometheus::BuildCounter()
                   .Name("tod_model_reloads_total")
                   .Help("Bundles a reload (SIGHUP) loaded or refused, by result")
                   .Register(*registry_)),
      token_reloads_(prometheus::BuildCounter()
                         .Name("tod_auth_token_reloads_total")
                         .Help("Bearer token file reloads (SIGHUP) by result")
                         .Register(*registry_)),
      model_frames_(prometheus::BuildCounter()
                        .Name("tod_model_frames_total")
                        .Help("Frames detected, by the model that served them")
                        .Register(*registry_)),
      geometry_(prometheus::BuildCounter()
                    .Name("tod_geometry_total")
                    .Help("Frames detected, by where their road geometry came from (bundle, "
                          "frame, camera)")
                    .Register(*registry_)),
      geometry_fallbacks_(prometheus::BuildCounter()
                              .Name("tod_geometry_fallbacks_total")
                              .Help("Frames whose geometry could not be calibrated and fell "
                                    "back to the bundle's")
                              .Register(*registry_)
                              .Add({})),
      cameras_(prometheus::BuildGauge()
                   .Name("tod_cameras_tracked")
                   .Help("Cameras whose horizon estimate the server keeps (camera_id, streams "
                         "not counted)")
                   .Register(*registry_)
                   .Add({})) {
  // Every reason from the start, so dashboards and alerts see 0 rather than no series.
  for (const CancelReason reason : kAllCancelReasons)
    cancelled_.Add({{"reason", CancelReasonName(reason)}});
  for (const char* stage : {"occlusion", "proposals", "regression"})
    degraded_.Add({{"stage", stage}});
  for (const HorizonSource source :
       {HorizonSource::kBundle, HorizonSource::kFrame, HorizonSource::kCamera})
    geometry_.Add({{"source", HorizonSourceName(source)}});
}

void ServerMetrics::RecordRequest(const std::string& protocol, const std::string& code,
                                  double seconds) {
  requests_.Add({{"protocol", protocol}, {"code", code}}).Increment();
  request_duration_.Add({{"protocol", protocol}}, LatencyBuckets()).Observe(seconds);
}

void ServerMetrics::RecordRejection(const std::string& reason) {
  rejections_.Add({{"reason", reason}}).Increment();
}

void ServerMetrics::RecordHttpRefusal(const std::string& reason) {
  http_refused_.Add({{"reason", reason}}).Increment();
}

void ServerMetrics::SetHttpConnections(double open) { http_connections_.Set(open); }

void ServerMetrics::OnAccepted(size_t queue_depth) {
  queue_depth_.Set(static_cast<double>(queue_depth));
  in_flight_.Increment();
}

void ServerMetrics::OnQueueDepth(size_t queue_depth) {
  queue_depth_.Set(static_cast<double>(queue_depth));
}

void ServerMetrics::OnStarted(double queue_ms) { queue_duration_.Observe(queue_ms / 1000.0); }

void ServerMetrics::OnFinished() { in_flight_.Decrement(); }

void ServerMetrics::OnRejected(Rejection rejection) { RecordRejection(RejectionName(rejection)); }

void ServerMetrics::OnCancelled(CancelReason reason) {
  cancelled_.Add({{"reason", CancelReasonName(reason)}}).Increment();
}

void ServerMetrics::OnDetected(const std::string& model, const StageTimes& timings,
                               const Detection& detection) {
  model_frames_.Add({{"model", model}}).Increment();
  for (const auto& [stage, ms] : timings) {
    stage_duration_.Add({{"stage", stage}}, LatencyBuckets()).Observe(ms / 1000.0);
  }
  for (const std::string& stage : detection.degraded_stages) {
    degraded_.Add({{"stage", stage}}).Increment();
  }
  geometry_.Add({{"source", HorizonSourceName(detection.horizon.source)}}).Increment();
  if (!detection.horizon.fallback.empty()) geometry_fallbacks_.Increment();
}

void ServerMetrics::OnCameras(size_t cameras) { cameras_.Set(static_cast<double>(cameras)); }

void ServerMetrics::SetModels(const std::vector<ModelSeries>& models) {
  // Only the models loaded now: drop the series of unloaded ones and of older generations.
  std::lock_guard lock(model_mutex_);
  for (prometheus::Gauge* series : model_series_) model_info_.Remove(series);
  model_series_.clear();
  for (const ModelSeries& model : models) {
    prometheus::Gauge& series = model_info_.Add({{"name", model.name},
                                                 {"version", model.version},
                                                 {"generation", std::to_string(model.generation)}});
    series.Set(1);
    model_series_.push_back(&series);
  }
}

void ServerMetrics::RecordReload(bool ok) {
  reloads_.Add({{"result", ok ? "success" : "failure"}}).Increment();
}

void ServerMetrics::RecordTokenReload(bool ok) {
  token_reloads_.Add({{"result", ok ? "success" : "failure"}}).Increment();
}

std::string ServerMetrics::SerializeText() const {
  return prometheus::TextSerializer().Serialize(registry_->Collect());
}

}  // namespace tod::server
