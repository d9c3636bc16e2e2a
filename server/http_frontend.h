// REST frontend: the tod REST API on the bounded HTTP transport (server/http/). Detection
// requests go through the same engine (queue, workers, limits) as gRPC; the JSON is the proto3
// JSON form of the same tod.v1 messages.
//
//   POST /v1/detect             body: JPEG/PNG/WebP; query: max_proposals, obstacle_threshold,
//                               map=png|none, frame_id, timeout_ms  -> DetectResponse JSON
//   POST /v1/probability-map    same input                          -> image/png map
//   GET  /v1/model                                                   -> ModelInfo JSON
//   GET  /v2/health/live, /v2/health/ready, /metrics
//   /v2, /v2/models/...         the Open Inference Protocol (KServe v2), server/oip/oip_rest.h
//
// No handler blocks an I/O thread: detection answers from the engine's completion. A client that
// disconnects while its detection runs cancels it (the transport's client_gone).
#pragma once

#include <atomic>
#include <boost/asio/ssl/context.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "core/base/status.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/http/http_limits.h"
#include "server/metrics.h"
#include "server/token_auth.h"

namespace tod::server {

namespace http {
class HttpServer;
}  // namespace http
class RestApi;

struct HttpFrontendConfig {
  http::HttpLimits limits;  // limits.max_body_bytes is the image byte limit
  int retry_after_s = 1;
  int io_threads = 2;
  std::shared_ptr<boost::asio::ssl::context> tls;  // HTTPS when set
  // When set, /v1/*, /v2 and /v2/models/* need a bearer token (checked from the header, before
  // the body is read); /v2/health/* and /metrics stay open for probes and scrapers.
  std::shared_ptr<const TokenAuthenticator> auth;
  // The tokens of the model repository calls (/v2/repository/..., oip/oip_repository.h); null:
  // those calls are refused. Told what a repository call changed.
  std::shared_ptr<const TokenAuthenticator> admin;
  std::function<void(const RepositoryChanges&)> on_models_changed = [](const RepositoryChanges&) {};
};

class HttpFrontend {
 public:
  HttpFrontend(HttpFrontendConfig config, InferenceEngine& engine, ModelHolder& models,
               ServerMetrics& metrics);
  ~HttpFrontend();
  HttpFrontend(const HttpFrontend&) = delete;
  HttpFrontend& operator=(const HttpFrontend&) = delete;

  // Binds the listening socket (port 0: any free port); the port is then port().
  Status Bind(const std::string& host, int port);
  int port() const;
  // Serves on the I/O threads until Stop().
  void Start();
  // Stops accepting, lets answers being written finish (up to `grace`), closes.
  void Stop(std::chrono::milliseconds grace = std::chrono::seconds(5));

 private:
  const HttpFrontendConfig config_;
  InferenceEngine& engine_;
  ModelHolder& models_;
  ServerMetrics& metrics_;
  std::atomic<uint64_t> request_counter_{0};
  std::unique_ptr<RestApi> api_;              // the handlers the routes call
  std::unique_ptr<http::HttpServer> server_;  // last: its connections use the members above
};

}  // namespace tod::server
