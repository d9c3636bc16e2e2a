// Prometheus metrics of the server (prometheus-cpp core; served as text on the REST /metrics).
// Names follow Prometheus conventions: base units (seconds), _total for counters.
#pragma once

#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/base/stage_timer.h"
#include "server/core/engine_observer.h"

namespace tod::server {

// The engine's events arrive through EngineObserver; the front ends, the HTTP transport and the
// model and token reloads call the Record*/Set* methods themselves.
class ServerMetrics final : public EngineObserver {
 public:
  ServerMetrics();

  // EngineObserver: queue depth and in-flight gauges, queue wait and stage histograms,
  // rejections ("reason" = RejectionName), cancellations ("reason" = CancelReasonName) and
  // frames the budget cut short ("stage").
  void OnAccepted(size_t queue_depth) override;
  void OnQueueDepth(size_t queue_depth) override;
  void OnStarted(double queue_ms) override;
  void OnFinished() override;
  void OnRejected(Rejection rejection) override;
  void OnCancelled(CancelReason reason) override;
  // Also counts each frame's geometry source (tod_geometry_total{source}) and the frames whose
  // geometry fell back to the bundle's (tod_geometry_fallbacks_total).
  void OnDetected(const std::string& model, const StageTimes& timings,
                  const Detection& detection) override;
  void OnCameras(size_t cameras) override;  // tod_cameras_tracked

  // One finished request. protocol: "grpc" | "http"; code: the gRPC code name ("OK", ...).
  void RecordRequest(const std::string& protocol, const std::string& code, double seconds);
  // A request refused before it reached the engine, or by the engine (OnRejected):
  // "unauthenticated", "bad_request", or a RejectionName.
  void RecordRejection(const std::string& reason);
  // The HTTP transport refused a request or connection (http::RefusalReasonName).
  void RecordHttpRefusal(const std::string& reason);
  void SetHttpConnections(double open);
  // tod_model_info: one series per loaded model (name, version, generation); SetModels replaces
  // them all with `models`.
  struct ModelSeries {
    std::string name;
    std::string version;
    int generation = 0;
  };
  void SetModels(const std::vector<ModelSeries>& models);
  void RecordReload(bool ok);
  void RecordTokenReload(bool ok);

  std::string SerializeText() const;

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Family<prometheus::Counter>& requests_;
  prometheus::Family<prometheus::Histogram>& request_duration_;
  prometheus::Histogram& queue_duration_;
  prometheus::Family<prometheus::Histogram>& stage_duration_;
  prometheus::Gauge& queue_depth_;
  prometheus::Gauge& in_flight_;
  prometheus::Family<prometheus::Counter>& rejections_;
  prometheus::Family<prometheus::Counter>& cancelled_;
  prometheus::Family<prometheus::Counter>& degraded_;
  prometheus::Family<prometheus::Counter>& http_refused_;
  prometheus::Gauge& http_connections_;
  prometheus::Family<prometheus::Gauge>& model_info_;
  prometheus::Family<prometheus::Counter>& reloads_;
  prometheus::Family<prometheus::Counter>& token_reloads_;
  prometheus::Family<prometheus::Counter>& model_frames_;
  prometheus::Family<prometheus::Counter>& geometry_;
  prometheus::Counter& geometry_fallbacks_;
  prometheus::Gauge& cameras_;
  std::mutex model_mutex_;                        // guards model_series_
  std::vector<prometheus::Gauge*> model_series_;  // the tod_model_info series (registry owns them)
};

}  // namespace tod::server
