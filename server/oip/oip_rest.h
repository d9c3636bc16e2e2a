// The Open Inference Protocol (KServe v2) REST API, next to the tod /v1 API on the same HTTP
// transport, engine, limits, metrics and access log:
//
//   GET  /v2                                           server metadata
//   GET  /v2/models/{name}[/versions/{v}]              model metadata (oip_model.h)
//   GET  /v2/models/{name}[/versions/{v}]/ready        200 ready, 503 not (yet) ready
//   POST /v2/models/{name}[/versions/{v}]/infer        detection (oip_tensors.h for the bodies)
//
// (/v2/health/live and /v2/health/ready are the frontend's probes.) Errors are the protocol's
// {"error": "<message>"} with the /v1 API's status codes (server/status_mapping.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <string_view>

#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/http/router.h"
#include "server/metrics.h"
#include "server/oip/oip_tensors.h"

namespace tod::server::oip {

// Whether `path` is part of this API and so needs the bearer token when auth is on: /v2 and
// /v2/models/...; /v2/health/* stays open for probes, /v2/repository/* takes the admin tokens.
bool NeedsToken(std::string_view path);

class OipRestApi {
 public:
  // The references must outlive the routes. `counter` numbers requests ("h<n>") with /v1's.
  OipRestApi(int retry_after_s, size_t max_image_bytes, InferenceEngine& engine,
             const ModelHolder& models, ServerMetrics& metrics, std::atomic<uint64_t>& counter);

  void AddRoutes(http::Router* router) const;

 private:
  void HandleGet(const http::IncomingRequest& request, const http::Responder& respond) const;
  void Infer(http::IncomingRequest incoming, http::Responder respond) const;

  const int retry_after_s_;
  const BodyLimits limits_;
  InferenceEngine& engine_;
  const ModelHolder& models_;
  ServerMetrics& metrics_;
  std::atomic<uint64_t>& counter_;
};

}  // namespace tod::server::oip
