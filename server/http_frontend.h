// REST frontend on cpp-httplib. Detection requests go through the same engine (queue, workers,
// limits) as gRPC; the JSON is the proto3 JSON form of the same tod.v1 messages.
//
//   POST /v1/detect             body: JPEG/PNG; query: max_proposals, obstacle_threshold,
//                               map=png|none, frame_id, timeout_ms  -> DetectResponse JSON
//   POST /v1/probability-map    same input                          -> image/png map
//   GET  /v1/model                                                   -> ModelInfo JSON
//   GET  /v2/health/live, /v2/health/ready, /metrics
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "core/base/status.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/metrics.h"

namespace httplib {
class Server;
struct Request;
struct Response;
}  // namespace httplib

namespace tod::server {

struct HttpFrontendConfig {
  size_t max_image_bytes = 16u << 20;
  int retry_after_s = 1;
  int threads = 16;
};

class HttpFrontend {
 public:
  HttpFrontend(HttpFrontendConfig config, InferenceEngine& engine, const ModelHolder& models,
               ServerMetrics& metrics);
  ~HttpFrontend();
  HttpFrontend(const HttpFrontend&) = delete;
  HttpFrontend& operator=(const HttpFrontend&) = delete;

  // Binds the listening socket (port 0: any free port); the port is then port().
  Status Bind(const std::string& host, int port);
  int port() const { return port_; }
  // Serves on a background thread until Stop().
  void Start();
  // Stops accepting, lets running handlers finish, joins.
  void Stop();

 private:
  void HandleDetect(const httplib::Request& request, httplib::Response& response, bool map_only);
  void HandleModel(httplib::Response& response);

  const HttpFrontendConfig config_;
  InferenceEngine& engine_;
  const ModelHolder& models_;
  ServerMetrics& metrics_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  std::atomic<bool> listener_done_{false};  // listen_after_bind() has returned
  int port_ = 0;
  std::atomic<uint64_t> request_counter_{0};
};

}  // namespace tod::server
