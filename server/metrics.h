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

#include "core/base/stage_timer.h"

namespace tod::server {

class ServerMetrics {
 public:
  ServerMetrics();

  // One finished request. protocol: "grpc" | "http"; code: the gRPC code name ("OK", ...).
  void RecordRequest(const std::string& protocol, const std::string& code, double seconds);
  // A request refused before or instead of running: "queue_full", "too_large", "bad_image",
  // "not_ready", "deadline", "bad_request".
  void RecordRejection(const std::string& reason);
  // A request whose work was stopped or skipped because its caller gave up or the drain timeout
  // came: "deadline", "client_cancelled", "client_disconnected", "drain" (CancelReasonName).
  void RecordCancelled(const std::string& reason);
  // The frame budget cut a stage of a request short ("proposals", "regression").
  void RecordDegraded(const std::string& stage);
  void ObserveQueueWait(double seconds);
  void ObserveStages(const StageTimes& stages);  // milliseconds in, seconds exported
  void SetQueueDepth(double depth);
  void AddInFlight(double delta);
  // The HTTP transport refused a request or connection (http::RefusalReasonName).
  void RecordHttpRefusal(const std::string& reason);
  void SetHttpConnections(double open);
  void SetModel(const std::string& name, const std::string& version, int generation);
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
  std::mutex model_mutex_;                     // guards model_series_
  prometheus::Gauge* model_series_ = nullptr;  // the one tod_model_info series (registry owns it)
};

}  // namespace tod::server
