#include "server/server_app.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <algorithm>
#include <condition_variable>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>

#include "core/base/atomic_file.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/grpc_frontend.h"
#include "server/http/http_limits.h"
#include "server/http_frontend.h"
#include "server/logging.h"
#include "server/metrics.h"
#include "server/oip/oip_grpc.h"
#include "server/tls_config.h"
#include "server/token_auth.h"

namespace tod::server {
namespace {

sigset_t ServerSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  return signals;
}

// gRPC rejects larger messages itself with a terse message; the slack lets a request somewhat over
// the image limit reach the engine and get our explanatory RESOURCE_EXHAUSTED instead.
constexpr size_t kGrpcMessageSlack = 1u << 20;

// tod_model_info for the models loaded now, and a log line for each model `changes` names
// (`refused_event` for the refused ones).
void PublishModels(const ModelHolder& models, const RepositoryChanges& changes,
                   ServerMetrics& metrics,
                   const char* refused_event =
                       "reload refused; the previous model of its name "
                       "(if any) keeps serving") {
  std::vector<ServerMetrics::ModelSeries> series;
  for (const std::shared_ptr<const LoadedModel>& model : models.Models()) {
    const ModelInfo& info = model->detector->info();
    series.push_back({info.name, info.version, model->generation});
    const auto& changed = changes.loaded;
    const auto& swapped = changes.swapped;
    if (std::find(changed.begin(), changed.end(), info.name) == changed.end() &&
        std::find(swapped.begin(), swapped.end(), info.name) == swapped.end()) {
      continue;
    }
    LogEvent(spdlog::level::info, "model loaded",
             {{"dir", model->model_dir},
              {"name", info.name},
              {"version", info.version},
              {"generation", model->generation},
              {"warm_up_ms", static_cast<long long>(model->warm_up_ms + 0.5)}});
  }
  metrics.SetModels(series);
  for (const std::string& name : changes.unloaded) {
    LogEvent(spdlog::level::info, "model unloaded", {{"name", name}});
  }
  for (const auto& [name, refused] : changes.refused) {
    LogEvent(spdlog::level::err, refused_event, {{"name", name}, {"error", refused.ToString()}});
  }
}

// The model or the repository of `config`; on failure nothing serves.
Result<RepositoryChanges> LoadModels(const ServerConfig& config, ModelHolder& models) {
  if (!config.model_repository.empty()) {
    return models.LoadRepository(config.model_repository, config.default_model);
  }
  if (Status loaded = models.Load(config.model_dir); !loaded.ok()) {
    return loaded.WithContext("cannot load model bundle " + config.model_dir);
  }
  RepositoryChanges changes;
  changes.loaded.push_back(models.Current()->name());
  return changes;
}

std::chrono::milliseconds Milliseconds(double seconds) {
  return std::chrono::milliseconds(static_cast<long long>(seconds * 1000));
}

http::HttpLimits HttpLimitsFrom(const ServerConfig& config) {
  http::HttpLimits limits;
  limits.max_header_bytes = static_cast<uint32_t>(config.http_max_header_bytes);
  limits.max_body_bytes = config.max_image_bytes;
  limits.max_buffered_bytes = config.http_max_buffered_bytes;
  limits.request_timeout = Milliseconds(config.http_request_timeout_s);
  limits.idle_timeout = Milliseconds(config.http_idle_timeout_s);
  limits.write_timeout = Milliseconds(config.http_write_timeout_s);
  limits.max_connections = config.http_max_connections;
  limits.max_connections_per_client = config.http_max_connections_per_client;
  return limits;
}

// The drain deadline is a hard limit: if shutting down still hangs (a pipeline stage that does not
// return, a front end that does not close) when `when` comes, the process exits anyway. Disarmed
// when it goes out of scope.
class ExitDeadline {
 public:
  explicit ExitDeadline(std::chrono::steady_clock::time_point when)
      : thread_([this, when] {
          std::unique_lock lock(mutex_);
          if (disarmed_.wait_until(lock, when, [this] { return done_; })) return;
          LogEvent(spdlog::level::err, "drain hard limit reached: exiting with work still running");
          spdlog::default_logger()->flush();
          std::_Exit(1);
        }) {}
  ~ExitDeadline() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    disarmed_.notify_all();
    thread_.join();
  }
  ExitDeadline(const ExitDeadline&) = delete;
  ExitDeadline& operator=(const ExitDeadline&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable disarmed_;
  bool done_ = false;
  std::thread thread_;  // last: starts after the members it uses
};

// What is left of `budget` until `limit`, at least 0.
std::chrono::milliseconds Within(std::chrono::milliseconds budget,
                                 std::chrono::steady_clock::time_point limit) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
      limit - std::chrono::steady_clock::now());
  return std::clamp(left, std::chrono::milliseconds(0), budget);
}

// Refuses to start: logs `event` with the error and says it on stderr; returns the exit code.
int Refuse(const char* event, const std::string& log_error, const std::string& message,
           int exit_code) {
  LogEvent(spdlog::level::err, event, {{"error", log_error}});
  std::cerr << "tod_server: " << message << "\n";
  return exit_code;
}

// TLS material and bearer tokens, both optional.
struct Security {
  std::optional<TlsMaterial> tls;
  std::shared_ptr<TokenAuthenticator> auth;
  std::shared_ptr<TokenAuthenticator> admin;  // the repository's load/unload calls
};

// TLS files and tokens are checked before anything listens: a typo must not start a server that
// is open (no tokens) or unreachable (no certificate). On failure, the exit code (2).
std::variant<Security, int> LoadSecurity(const ServerConfig& config) {
  Security security;
  if (const TlsFiles files{config.tls_cert, config.tls_key, config.tls_client_ca};
      files.enabled()) {
    Result<TlsMaterial> loaded = LoadTlsMaterial(files);
    if (!loaded.ok()) {
      const std::string& error = loaded.status().message();
      return Refuse("tls refused", error, error, 2);
    }
    security.tls = std::move(*loaded);
  }
  if (!config.auth_token_file.empty()) {
    Result<std::shared_ptr<TokenAuthenticator>> loaded =
        TokenAuthenticator::FromFile(config.auth_token_file);
    if (!loaded.ok()) {
      const std::string& error = loaded.status().message();
      return Refuse("auth tokens refused", error, error, 2);
    }
    security.auth = std::move(*loaded);
    LogEvent(spdlog::level::info, "auth tokens loaded", {{"tokens", security.auth->token_count()}});
  }
  if (!config.admin_token_file.empty()) {
    Result<std::shared_ptr<TokenAuthenticator>> loaded =
        TokenAuthenticator::FromFile(config.admin_token_file);
    if (!loaded.ok()) {
      const std::string& error = loaded.status().message();
      return Refuse("admin tokens refused", error, error, 2);
    }
    security.admin = std::move(*loaded);
    LogEvent(spdlog::level::info, "admin tokens loaded",
             {{"tokens", security.admin->token_count()}});
  }
  return security;
}

EngineConfig EngineConfigFrom(const ServerConfig& config) {
  EngineConfig engine;
  engine.workers = config.workers;
  engine.threads_per_request = config.threads_per_request;
  engine.frame_budget_ms = config.frame_budget_ms;
  engine.queue_capacity = config.queue;
  engine.cameras.max_cameras = static_cast<size_t>(config.max_cameras);
  engine.cameras.idle_seconds = config.camera_idle_s;
  engine.limits.max_bytes = config.max_image_bytes;
  engine.limits.max_pixels = config.max_image_pixels;
  return engine;
}

// The gRPC listener with health checking and reflection, reporting not-serving until the model is
// loaded; *port receives the bound port. Null when it cannot listen.
std::unique_ptr<grpc::Server> StartGrpc(const ServerConfig& config, const Security& security,
                                        ObstacleDiscoveryService& service,
                                        oip::OipGrpcService& oip_service, int* port) {
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  const std::string address = config.host + ":" + std::to_string(config.grpc_port);
  builder.AddListeningPort(
      address,
      security.tls ? GrpcServerCredentials(*security.tls) : grpc::InsecureServerCredentials(),
      port);
  builder.SetMaxReceiveMessageSize(static_cast<int>(config.max_image_bytes + kGrpcMessageSlack));
  builder.RegisterService(&service);
  builder.RegisterService(&oip_service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || *port == 0) return nullptr;
  grpc::HealthCheckServiceInterface* health = server->GetHealthCheckService();
  // Register the service's own name too (grpc.health.v1 answers NOT_FOUND for unknown names);
  // SetServingStatus(bool) then switches "" and this name together.
  health->SetServingStatus(tod::v1::ObstacleDiscovery::service_full_name(), false);
  health->SetServingStatus(inference::GRPCInferenceService::service_full_name(), false);
  health->SetServingStatus(false);
  return server;
}

HttpFrontendConfig HttpConfigFrom(const ServerConfig& config, const Security& security) {
  HttpFrontendConfig http;
  http.limits = HttpLimitsFrom(config);
  http.retry_after_s = config.retry_after_s;
  http.io_threads = config.http_threads;
  http.auth = security.auth;
  http.admin = security.admin;
  return http;
}

// SIGHUP: the model bundle (or the repository) and the tokens again; a refused bundle leaves
// the previous one of its name in service.
void Reload(const ServerConfig& config, ModelHolder& models, ServerMetrics& metrics,
            const std::vector<TokenAuthenticator*>& token_files) {
  LogEvent(spdlog::level::info, "reloading models",
           {{"dir", config.model_repository.empty() ? config.model_dir : config.model_repository}});
  const RepositoryChanges changes = models.Reload();
  // One count per bundle the reload loaded, swapped or refused (one bundle: one count).
  for (size_t i = 0; i < changes.loaded.size() + changes.swapped.size(); ++i) {
    metrics.RecordReload(true);
  }
  for (size_t i = 0; i < changes.refused.size(); ++i) metrics.RecordReload(false);
  PublishModels(models, changes, metrics);
  for (TokenAuthenticator* auth : token_files) {
    if (auth == nullptr) continue;
    const Status tokens = auth->Reload();
    metrics.RecordTokenReload(tokens.ok());
    if (tokens.ok()) {
      LogEvent(spdlog::level::info, "auth tokens reloaded",
               {{"file", auth->path()}, {"tokens", auth->token_count()}});
    } else {
      LogEvent(spdlog::level::err, "token reload refused; the previous tokens stay",
               {{"file", auth->path()}, {"error", tokens.message()}});
    }
  }
}

// Serves until SIGTERM or SIGINT (returned), reloading on every SIGHUP.
int ServeUntilStopSignal(const ServerConfig& config, ModelHolder& models, ServerMetrics& metrics,
                         const std::vector<TokenAuthenticator*>& token_files) {
  const sigset_t signals = ServerSignals();
  for (;;) {
    int signal_number = 0;
    if (sigwait(&signals, &signal_number) != 0) continue;
    if (signal_number != SIGHUP) return signal_number;
    Reload(config, models, metrics, token_files);
  }
}

// Drain: refuse new work and report not-serving, let admitted work finish until the drain
// deadline, then answer what is still queued with UNAVAILABLE / 503 and cancel what runs (it
// stops at its next stage boundary). Everything after the deadline has one second in all:
// answers being written get what is left of it, and the process exits at the latest then.
void Drain(const ServerConfig& config, InferenceEngine& engine, grpc::Server& grpc_server,
           HttpFrontend& http) {
  using std::chrono::milliseconds;
  using std::chrono::steady_clock;
  engine.BeginDrain();
  grpc_server.GetHealthCheckService()->SetServingStatus(false);
  const steady_clock::time_point drain_deadline =
      steady_clock::now() + Milliseconds(config.drain_timeout_s);
  const steady_clock::time_point hard_limit = drain_deadline + milliseconds(950);
  const bool drained = engine.WaitIdle(drain_deadline);
  ExitDeadline exit_deadline(hard_limit);
  if (!drained) {
    LogEvent(spdlog::level::warn,
             "drain timeout: queued requests are refused, running ones cancelled",
             {{"queued", engine.queue_depth()}});
    engine.CancelAll(CancelReason::kDrain);
    if (!engine.WaitIdle(drain_deadline + milliseconds(500))) {
      LogEvent(spdlog::level::warn, "drain timeout: a pipeline stage is still running");
    }
  }
  // Calls still open (an idle DetectStream, say) are cancelled at the gRPC deadline.
  grpc_server.Shutdown(std::chrono::system_clock::now() +
                       Within(milliseconds(2000), hard_limit - milliseconds(250)));
  http.Stop(Within(milliseconds(5000), hard_limit - milliseconds(100)));
  engine.Stop();
  LogEvent(spdlog::level::info, "stopped", {{"drained", drained}});
}

// The HTTP front end's settings, with the HTTPS context when TLS is on.
Result<HttpFrontendConfig> HttpConfigWithTls(const ServerConfig& config, const Security& security) {
  HttpFrontendConfig http_config = HttpConfigFrom(config, security);
  if (security.tls) {
    Result<std::shared_ptr<boost::asio::ssl::context>> https = HttpsContext(*security.tls);
    if (!https.ok()) return https.status();
    http_config.tls = std::move(*https);
  }
  return http_config;
}

void LogListening(const ServerConfig& config, const Security& security, int grpc_port,
                  int http_port) {
  LogEvent(spdlog::level::info, "listening",
           {{"grpc", config.host + ":" + std::to_string(grpc_port)},
            {"http", config.host + ":" + std::to_string(http_port)},
            {"tls", !security.tls            ? "off"
                    : security.tls->mutual() ? "mutual"
                                             : "on"},
            {"auth", security.auth ? "bearer" : "off"}});
}

// The bound ports for whoever started us (tests, supervisors) when the kernel picked them,
// written atomically so a reader never sees half a file.
Status WritePortsFile(const std::string& path, int grpc_port, int http_port) {
  return WriteFileAtomically(
      path, nlohmann::json{{"grpc", grpc_port}, {"http", http_port}}.dump() + "\n");
}

}  // namespace

void BlockServerSignals() {
  const sigset_t signals = ServerSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
}

int RunServer(const ServerConfig& config) {
  BlockServerSignals();  // before any thread starts, so all of them inherit the mask
  LogEvent(spdlog::level::info, "starting", ServerConfigToJson(config));
  std::variant<Security, int> loaded_security = LoadSecurity(config);
  if (const int* exit_code = std::get_if<int>(&loaded_security)) return *exit_code;
  const Security& security = std::get<Security>(loaded_security);

  ServerMetrics metrics;
  ModelHolder models;
  InferenceEngine engine(EngineConfigFrom(config), models, &metrics);
  engine.Start();

  // Listeners come up first and report not-ready until the model is loaded, so orchestrators
  // can tell "starting" from "dead".
  ObstacleDiscoveryService service(engine, models, metrics, security.auth);
  oip::OipGrpcService oip_service(
      engine, models, metrics, config.max_image_bytes,
      [&service] { return service.NextRequestId(); }, security.auth);
  int grpc_port = 0;
  std::unique_ptr<grpc::Server> grpc_server =
      StartGrpc(config, security, service, oip_service, &grpc_port);
  if (!grpc_server) {
    const std::string address = config.host + ":" + std::to_string(config.grpc_port);
    LogEvent(spdlog::level::err, "cannot listen for gRPC", {{"address", address}});
    std::cerr << "tod_server: cannot listen for gRPC on " << address
              << " (port in use or not permitted)\n";
    return 1;
  }
  Result<HttpFrontendConfig> http_config = HttpConfigWithTls(config, security);
  if (!http_config.ok()) {  // LoadTlsMaterial built one already; this cannot fail differently
    std::cerr << "tod_server: " << http_config.status().message() << "\n";
    grpc_server->Shutdown();
    return 2;
  }
  http_config->on_models_changed = [&models, &metrics](const RepositoryChanges& changes) {
    PublishModels(models, changes, metrics);
  };
  HttpFrontend http(*http_config, engine, models, metrics);
  if (Status bound = http.Bind(config.host, config.http_port); !bound.ok()) {
    grpc_server->Shutdown();
    return Refuse("cannot listen for HTTP", bound.message(), bound.message(), 1);
  }
  http.Start();
  LogListening(config, security, grpc_port, http.port());
  if (!config.ports_file.empty()) {
    if (Status written = WritePortsFile(config.ports_file, grpc_port, http.port()); !written.ok()) {
      http.Stop();
      grpc_server->Shutdown();
      return Refuse("cannot write the ports file", written.message(), written.message(), 1);
    }
  }

  const Result<RepositoryChanges> loaded = LoadModels(config, models);
  if (!loaded.ok()) {
    http.Stop();
    grpc_server->Shutdown();
    return Refuse("model bundle refused", loaded.status().ToString(), loaded.status().message(), 1);
  }
  PublishModels(models, *loaded, metrics, "model refused; the other models serve");
  grpc_server->GetHealthCheckService()->SetServingStatus(true);
  LogEvent(spdlog::level::info, "ready");

  const int stop_signal =
      ServeUntilStopSignal(config, models, metrics, {security.auth.get(), security.admin.get()});
  LogEvent(spdlog::level::info, "draining",
           {{"signal", stop_signal == SIGTERM ? "SIGTERM" : "SIGINT"},
            {"queued", engine.queue_depth()},
            {"timeout_s", config.drain_timeout_s}});
  Drain(config, engine, *grpc_server, http);
  spdlog::default_logger()->flush();
  return 0;
}

}  // namespace tod::server
