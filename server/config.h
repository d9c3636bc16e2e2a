// Server configuration from three sources, lowest to highest precedence: an optional JSON file
// (--config / TOD_CONFIG), TOD_* environment variables, command-line flags.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"

namespace tod::server {

struct ServerConfig {
  // The bundle to serve, or (model_repository) a directory of bundles: exactly one is given.
  std::string model_dir;
  std::string model_repository;
  std::string default_model;  // repository: the model of requests that name none
  // Bearer tokens of the repository's load/unload calls (POST /v2/repository/models/...);
  // empty: those calls are off.
  std::string admin_token_file;
  std::string host = "0.0.0.0";  // bind address of both listeners
  int grpc_port = 8001;
  int http_port = 8000;
  // Where to write the bound ports once both listen, as {"grpc":P,"http":P} (written to a
  // temporary name and renamed); with port 0 the kernel picks free ports and this says which.
  std::string ports_file;
  int workers = 0;                     // 0: one per core
  int threads_per_request = 1;         // cores one request may use
  double frame_budget_ms = 2000;       // decode to map; 0: no budget
  int queue = 64;                      // requests waiting for a worker
  size_t max_image_bytes = 16u << 20;  // encoded request body
  // The shipped model's camera frames are 2048 x 1024 (2.1 MP); 4 MP leaves headroom while a
  // bigger frame would only cost seconds of CPU and hundreds of MB per request.
  long long max_image_pixels = 4'000'000;
  // Cameras (camera_id) whose horizon estimate is kept, and how long an unseen one is kept.
  int max_cameras = 1024;
  double camera_idle_s = 600;
  double drain_timeout_s = 20;  // SIGTERM: time allowed for queued + running work
  int retry_after_s = 1;        // Retry-After on 503 (queue full)
  int http_threads = 2;         // REST I/O threads (connections are asynchronous)
  // REST transport limits (server/http/http_limits.h).
  int http_max_connections = 512;
  int http_max_connections_per_client = 64;
  size_t http_max_header_bytes = 16 * 1024;
  size_t http_max_buffered_bytes = 256u << 20;
  double http_request_timeout_s = 30;  // first byte to last body byte of one request
  double http_idle_timeout_s = 60;     // connection without a request in progress
  double http_write_timeout_s = 30;    // writing one response
  // TLS on both listeners (both files, or neither); a client CA turns on mutual TLS.
  std::string tls_cert;
  std::string tls_key;
  std::string tls_client_ca;
  // Bearer tokens, one a line, reloaded on SIGHUP; empty: no authentication.
  std::string auth_token_file;
  std::string log_format = "text";  // text | json
  std::string log_level = "info";   // trace | debug | info | warn | error
};

// Absolute pixel ceiling no configuration may exceed (decompression-bomb guard).
inline constexpr long long kAbsoluteMaxPixels = 100'000'000;

// The settings: JSON key, flag (without "--"), environment variable, help.
struct SettingSpec {
  std::string key;
  std::string flag;
  std::string env;
  std::string help;
};
const std::vector<SettingSpec>& SettingSpecs();

// Sets one setting from text; `source` names where it came from, for the error message.
Status ApplySetting(const std::string& key, const std::string& value, const std::string& source,
                    ServerConfig* config);
// Applies a JSON object of settings (keys as in SettingSpecs). Unknown keys are errors.
Status ApplyJsonSettings(const nlohmann::json& settings, const std::string& source,
                         ServerConfig* config);

using EnvLookup = std::function<const char*(const char*)>;

// Defaults < file < environment < flags. `flags` maps SettingSpec::key (or "config") to the
// flag's text. Checks the result (required model, port ranges, positive sizes).
Result<ServerConfig> ResolveServerConfig(const std::map<std::string, std::string>& flags,
                                         const EnvLookup& env);

Status ValidateServerConfig(const ServerConfig& config);
nlohmann::json ServerConfigToJson(const ServerConfig& config);

}  // namespace tod::server
