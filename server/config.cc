#include "server/config.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <thread>

namespace tod::server {
namespace {

template <typename T>
Status ParseNumber(const std::string& text, const std::string& what, T* out) {
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(begin, end, *out);
  if (ec != std::errc() || ptr != end || text.empty()) {
    return Status::InvalidArgument(what + ": '" + text + "' is not a valid number");
  }
  return Status::Ok();
}

std::string JsonValueAsText(const nlohmann::json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

}  // namespace

const std::vector<SettingSpec>& SettingSpecs() {
  static const std::vector<SettingSpec> specs = {
      {"model", "model", "TOD_MODEL", "Model bundle directory (this or --model-repository)"},
      {"model_repository", "model-repository", "TOD_MODEL_REPOSITORY",
       "Directory of model bundles, each served by its directory name; rescanned on SIGHUP"},
      {"default_model", "default-model", "TOD_DEFAULT_MODEL",
       "With --model-repository: the model of requests that name none (default: 'default' when "
       "there is one, else the first by name)"},
      {"admin_token_file", "admin-token-file", "TOD_ADMIN_TOKEN_FILE",
       "Bearer tokens of POST /v2/repository/models/{name}/load|unload (off without it)"},
      {"host", "host", "TOD_HOST", "Bind address for both listeners (default 0.0.0.0)"},
      {"grpc_port", "grpc-port", "TOD_GRPC_PORT", "gRPC port (default 8001)"},
      {"http_port", "http-port", "TOD_HTTP_PORT", "REST port (default 8000)"},
      {"ports_file", "ports-file", "TOD_PORTS_FILE",
       "Write the bound ports as JSON {\"grpc\":P,\"http\":P} here once listening (with port 0: "
       "free ports the kernel picked)"},
      {"workers", "workers", "TOD_WORKERS", "Worker threads (default: number of cores)"},
      {"threads_per_request", "threads-per-request", "TOD_THREADS_PER_REQUEST",
       "Cores one request may use: window scans, features and regressors split over them "
       "(default 1; workers x this should not exceed the cores)"},
      {"frame_budget_ms", "frame-budget-ms", "TOD_FRAME_BUDGET_MS",
       "Time a frame may take from decode to map, ms; past it, proposals and regression degrade "
       "and the response says so (default 2000, 0: none)"},
      {"queue", "queue", "TOD_QUEUE", "Requests allowed to wait for a worker (default 64)"},
      {"max_image_bytes", "max-image-bytes", "TOD_MAX_IMAGE_BYTES",
       "Largest encoded image accepted, bytes (default 16 MiB)"},
      {"max_image_pixels", "max-image-pixels", "TOD_MAX_IMAGE_PIXELS",
       "Largest image accepted, width*height (default 4e6, at most 1e8)"},
      {"max_cameras", "max-cameras", "TOD_MAX_CAMERAS",
       "Cameras (camera_id) whose horizon estimate is kept; the least recently seen is "
       "forgotten to admit a new one (default 1024)"},
      {"camera_idle_s", "camera-idle", "TOD_CAMERA_IDLE",
       "Seconds a camera that sends no frame keeps its horizon estimate (default 600)"},
      {"drain_timeout_s", "drain-timeout", "TOD_DRAIN_TIMEOUT",
       "Seconds SIGTERM waits for queued and running work (default 20)"},
      {"retry_after_s", "retry-after", "TOD_RETRY_AFTER",
       "Retry-After seconds sent with 503 queue-full (default 1)"},
      {"http_threads", "http-threads", "TOD_HTTP_THREADS", "REST I/O threads (default 2)"},
      {"http_max_connections", "http-max-connections", "TOD_HTTP_MAX_CONNECTIONS",
       "Open REST connections allowed (default 512)"},
      {"http_max_connections_per_client", "http-max-connections-per-client",
       "TOD_HTTP_MAX_CONNECTIONS_PER_CLIENT",
       "Open REST connections allowed from one client address (default 64)"},
      {"http_max_header_bytes", "http-max-header-bytes", "TOD_HTTP_MAX_HEADER_BYTES",
       "Request line + headers, bytes (default 16384)"},
      {"http_max_buffered_bytes", "http-max-buffered-bytes", "TOD_HTTP_MAX_BUFFERED_BYTES",
       "Request body bytes all REST connections may hold together (default 256 MiB)"},
      {"http_request_timeout_s", "http-request-timeout", "TOD_HTTP_REQUEST_TIMEOUT",
       "Seconds from a request's first byte to its last (default 30)"},
      {"http_idle_timeout_s", "http-idle-timeout", "TOD_HTTP_IDLE_TIMEOUT",
       "Seconds a REST connection may wait idle for its next request (default 60)"},
      {"http_write_timeout_s", "http-write-timeout", "TOD_HTTP_WRITE_TIMEOUT",
       "Seconds allowed for writing one response (default 30)"},
      {"tls_cert", "tls-cert", "TOD_TLS_CERT",
       "PEM certificate chain: serve gRPC and HTTPS over TLS (with --tls-key)"},
      {"tls_key", "tls-key", "TOD_TLS_KEY", "PEM private key of --tls-cert"},
      {"tls_client_ca", "tls-client-ca", "TOD_TLS_CLIENT_CA",
       "PEM CA certificates: require client certificates it signed (mutual TLS)"},
      {"auth_token_file", "auth-token-file", "TOD_AUTH_TOKEN_FILE",
       "Bearer tokens, one a line (reloaded on SIGHUP): Detect, DetectStream, GetModelInfo, "
       "/v1/*, /v2 and /v2/models/* need 'authorization: Bearer <token>'"},
      {"log_format", "log-format", "TOD_LOG_FORMAT", "text | json (default text)"},
      {"log_level", "log-level", "TOD_LOG_LEVEL", "trace|debug|info|warn|error (default info)"},
  };
  return specs;
}

Status ApplySetting(const std::string& key, const std::string& value, const std::string& source,
                    ServerConfig* config) {
  const std::string what = source + " " + key;
  if (key == "model") {
    config->model_dir = value;
  } else if (key == "model_repository") {
    config->model_repository = value;
  } else if (key == "default_model") {
    config->default_model = value;
  } else if (key == "admin_token_file") {
    config->admin_token_file = value;
  } else if (key == "host") {
    config->host = value;
  } else if (key == "grpc_port") {
    return ParseNumber(value, what, &config->grpc_port);
  } else if (key == "http_port") {
    return ParseNumber(value, what, &config->http_port);
  } else if (key == "ports_file") {
    config->ports_file = value;
  } else if (key == "workers") {
    return ParseNumber(value, what, &config->workers);
  } else if (key == "threads_per_request") {
    return ParseNumber(value, what, &config->threads_per_request);
  } else if (key == "frame_budget_ms") {
    return ParseNumber(value, what, &config->frame_budget_ms);
  } else if (key == "queue") {
    return ParseNumber(value, what, &config->queue);
  } else if (key == "max_image_bytes") {
    return ParseNumber(value, what, &config->max_image_bytes);
  } else if (key == "max_image_pixels") {
    return ParseNumber(value, what, &config->max_image_pixels);
  } else if (key == "max_cameras") {
    return ParseNumber(value, what, &config->max_cameras);
  } else if (key == "camera_idle_s") {
    return ParseNumber(value, what, &config->camera_idle_s);
  } else if (key == "drain_timeout_s") {
    return ParseNumber(value, what, &config->drain_timeout_s);
  } else if (key == "retry_after_s") {
    return ParseNumber(value, what, &config->retry_after_s);
  } else if (key == "http_threads") {
    return ParseNumber(value, what, &config->http_threads);
  } else if (key == "http_max_connections") {
    return ParseNumber(value, what, &config->http_max_connections);
  } else if (key == "http_max_connections_per_client") {
    return ParseNumber(value, what, &config->http_max_connections_per_client);
  } else if (key == "http_max_header_bytes") {
    return ParseNumber(value, what, &config->http_max_header_bytes);
  } else if (key == "http_max_buffered_bytes") {
    return ParseNumber(value, what, &config->http_max_buffered_bytes);
  } else if (key == "http_request_timeout_s") {
    return ParseNumber(value, what, &config->http_request_timeout_s);
  } else if (key == "http_idle_timeout_s") {
    return ParseNumber(value, what, &config->http_idle_timeout_s);
  } else if (key == "http_write_timeout_s") {
    return ParseNumber(value, what, &config->http_write_timeout_s);
  } else if (key == "tls_cert") {
    config->tls_cert = value;
  } else if (key == "tls_key") {
    config->tls_key = value;
  } else if (key == "tls_client_ca") {
    config->tls_client_ca = value;
  } else if (key == "auth_token_file") {
    config->auth_token_file = value;
  } else if (key == "log_format") {
    config->log_format = value;
  } else if (key == "log_level") {
    config->log_level = value;
  } else {
    return Status::InvalidArgument(source + ": unknown setting '" + key + "'");
  }
  return Status::Ok();
}

Status ApplyJsonSettings(const nlohmann::json& settings, const std::string& source,
                         ServerConfig* config) {
  if (!settings.is_object()) {
    return Status::InvalidArgument(source + ": expected a JSON object of settings");
  }
  for (const auto& [key, value] : settings.items()) {
    if (value.is_object() || value.is_array() || value.is_null()) {
      return Status::InvalidArgument(source + ": setting '" + key + "' must be a scalar");
    }
    if (Status s = ApplySetting(key, JsonValueAsText(value), source, config); !s.ok()) return s;
  }
  return Status::Ok();
}

Result<ServerConfig> ResolveServerConfig(const std::map<std::string, std::string>& flags,
                                         const EnvLookup& env) {
  ServerConfig config;
  std::string config_file;
  if (auto it = flags.find("config"); it != flags.end()) {
    config_file = it->second;
  } else if (const char* from_env = env("TOD_CONFIG"); from_env != nullptr && *from_env) {
    config_file = from_env;
  }
  if (!config_file.empty()) {
    std::ifstream in(config_file);
    if (!in) return Status::NotFound("config file " + config_file + ": cannot open");
    nlohmann::json settings;
    try {
      in >> settings;
    } catch (const nlohmann::json::exception& e) {
      return Status::InvalidArgument("config file " + config_file + ": invalid JSON: " + e.what());
    }
    if (Status s = ApplyJsonSettings(settings, "config file " + config_file, &config); !s.ok()) {
      return s;
    }
  }
  for (const SettingSpec& spec : SettingSpecs()) {
    if (const char* value = env(spec.env.c_str()); value != nullptr && *value) {
      if (Status s = ApplySetting(spec.key, value, "environment " + spec.env, &config); !s.ok()) {
        return s;
      }
    }
  }
  for (const auto& [key, value] : flags) {
    if (key == "config") continue;
    if (Status s = ApplySetting(key, value, "flag", &config); !s.ok()) return s;
  }
  if (config.workers == 0) {
    config.workers = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  }
  if (Status s = ValidateServerConfig(config); !s.ok()) return s;
  return config;
}

namespace {

// Ports, workers, threads, the frame budget and the queue.
Status ValidateServing(const ServerConfig& config) {
  auto port_ok = [](int port) { return port >= 0 && port <= 65535; };
  if (!port_ok(config.grpc_port)) return Status::InvalidArgument("grpc_port: not in 0..65535");
  if (!port_ok(config.http_port)) return Status::InvalidArgument("http_port: not in 0..65535");
  if (config.grpc_port != 0 && config.grpc_port == config.http_port) {
    return Status::InvalidArgument("grpc_port and http_port must differ");
  }
  if (config.workers < 1 || config.workers > 1024) {
    return Status::InvalidArgument("workers: must be in 1..1024");
  }
  if (config.threads_per_request < 1 || config.threads_per_request > 64) {
    return Status::InvalidArgument("threads_per_request: must be in 1..64");
  }
  if (!(config.frame_budget_ms >= 0 && config.frame_budget_ms <= 600'000)) {
    return Status::InvalidArgument("frame_budget_ms: must be in 0..600000 (0: no budget)");
  }
  if (config.queue < 0) return Status::InvalidArgument("queue: must be >= 0");
  if (config.max_cameras < 1 || config.max_cameras > 1'000'000) {
    return Status::InvalidArgument("max_cameras: must be in 1..1000000");
  }
  if (!(config.camera_idle_s >= 1 && config.camera_idle_s <= 7 * 86400)) {
    return Status::InvalidArgument("camera_idle_s: must be in 1..604800 seconds");
  }
  return Status::Ok();
}

// What one image may cost before it is decoded.
Status ValidateImageLimits(const ServerConfig& config) {
  if (config.max_image_bytes < 64 || config.max_image_bytes > (1u << 30)) {
    return Status::InvalidArgument("max_image_bytes: must be in 64..1073741824");
  }
  if (config.max_image_pixels < 1 || config.max_image_pixels > kAbsoluteMaxPixels) {
    return Status::InvalidArgument("max_image_pixels: must be in 1.." +
                                   std::to_string(kAbsoluteMaxPixels));
  }
  return Status::Ok();
}

// What one HTTP connection may hold, and for how long; drain and retry advice.
Status ValidateHttpLimits(const ServerConfig& config) {
  if (!(config.drain_timeout_s >= 0 && config.drain_timeout_s <= 86400)) {
    return Status::InvalidArgument("drain_timeout_s: must be in 0..86400 seconds");
  }
  if (config.retry_after_s < 0 || config.retry_after_s > 3600) {
    return Status::InvalidArgument("retry_after_s: must be in 0..3600");
  }
  if (config.http_threads < 1 || config.http_threads > 64) {
    return Status::InvalidArgument("http_threads: must be in 1..64");
  }
  if (config.http_max_connections < 1 || config.http_max_connections > 100'000) {
    return Status::InvalidArgument("http_max_connections: must be in 1..100000");
  }
  if (config.http_max_connections_per_client < 1 ||
      config.http_max_connections_per_client > config.http_max_connections) {
    return Status::InvalidArgument(
        "http_max_connections_per_client: must be in 1..http_max_connections");
  }
  if (config.http_max_header_bytes < 1024 || config.http_max_header_bytes > (1u << 20)) {
    return Status::InvalidArgument("http_max_header_bytes: must be in 1024..1048576");
  }
  if (config.http_max_buffered_bytes < config.max_image_bytes ||
      config.http_max_buffered_bytes > (size_t{1} << 36)) {
    return Status::InvalidArgument(
        "http_max_buffered_bytes: must be at least max_image_bytes and at most 64 GiB");
  }
  const std::pair<const char*, double> timeouts[] = {
      {"http_request_timeout_s", config.http_request_timeout_s},
      {"http_idle_timeout_s", config.http_idle_timeout_s},
      {"http_write_timeout_s", config.http_write_timeout_s}};
  for (const auto& [name, seconds] : timeouts) {
    if (!(seconds >= 0.1 && seconds <= 3600)) {  // also refuses NaN
      return Status::InvalidArgument(std::string(name) + ": must be in 0.1..3600 seconds");
    }
  }
  return Status::Ok();
}

// TLS files come in pairs; the log format and level are known ones.
Status ValidateTlsAndLogging(const ServerConfig& config) {
  if (config.tls_cert.empty() != config.tls_key.empty()) {
    return Status::InvalidArgument("tls_cert and tls_key: give both or neither");
  }
  if (!config.tls_client_ca.empty() && config.tls_cert.empty()) {
    return Status::InvalidArgument("tls_client_ca: needs tls_cert and tls_key");
  }
  if (config.log_format != "text" && config.log_format != "json") {
    return Status::InvalidArgument("log_format: '" + config.log_format + "' is not text or json");
  }
  static const std::vector<std::string> levels = {"trace", "debug", "info", "warn", "error"};
  if (std::find(levels.begin(), levels.end(), config.log_level) == levels.end()) {
    return Status::InvalidArgument("log_level: '" + config.log_level + "' is not one of " +
                                   "trace, debug, info, warn, error");
  }
  return Status::Ok();
}

}  // namespace

Status ValidateServerConfig(const ServerConfig& config) {
  if (config.model_dir.empty() == config.model_repository.empty()) {
    return Status::InvalidArgument(
        config.model_dir.empty()
            ? "model: no model bundle given (--model DIR or --model-repository DIR)"
            : "model: give --model DIR or --model-repository DIR, not both");
  }
  if (!config.default_model.empty() && config.model_repository.empty()) {
    return Status::InvalidArgument("default_model: only with --model-repository");
  }
  if (!config.admin_token_file.empty() && config.model_repository.empty()) {
    return Status::InvalidArgument("admin_token_file: only with --model-repository");
  }
  for (const auto step :
       {ValidateServing, ValidateImageLimits, ValidateHttpLimits, ValidateTlsAndLogging}) {
    if (Status st = step(config); !st.ok()) return st;
  }
  return Status::Ok();
}

nlohmann::json ServerConfigToJson(const ServerConfig& config) {
  return {{"model", config.model_dir},
          {"model_repository", config.model_repository},
          {"default_model", config.default_model},
          {"admin_token_file", config.admin_token_file},
          {"host", config.host},
          {"grpc_port", config.grpc_port},
          {"http_port", config.http_port},
          {"ports_file", config.ports_file},
          {"workers", config.workers},
          {"threads_per_request", config.threads_per_request},
          {"frame_budget_ms", config.frame_budget_ms},
          {"queue", config.queue},
          {"max_image_bytes", config.max_image_bytes},
          {"max_image_pixels", config.max_image_pixels},
          {"max_cameras", config.max_cameras},
          {"camera_idle_s", config.camera_idle_s},
          {"drain_timeout_s", config.drain_timeout_s},
          {"retry_after_s", config.retry_after_s},
          {"http_threads", config.http_threads},
          {"http_max_connections", config.http_max_connections},
          {"http_max_connections_per_client", config.http_max_connections_per_client},
          {"http_max_header_bytes", config.http_max_header_bytes},
          {"http_max_buffered_bytes", config.http_max_buffered_bytes},
          {"http_request_timeout_s", config.http_request_timeout_s},
          {"http_idle_timeout_s", config.http_idle_timeout_s},
          {"http_write_timeout_s", config.http_write_timeout_s},
          {"tls_cert", config.tls_cert},
          {"tls_key", config.tls_key},
          {"tls_client_ca", config.tls_client_ca},
          {"auth_token_file", config.auth_token_file},
          {"log_format", config.log_format},
          {"log_level", config.log_level}};
}

}  // namespace tod::server
