#include "server/server_app.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>

#include <csignal>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/grpc_frontend.h"
#include "server/http/http_limits.h"
#include "server/http_frontend.h"
#include "server/logging.h"
#include "server/metrics.h"

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

void PublishModel(const ModelHolder& models, ServerMetrics& metrics) {
  const std::shared_ptr<const LoadedModel> model = models.Current();
  if (!model) return;
  const ModelInfo& info = model->detector->info();
  metrics.SetModel(info.name, info.version, model->generation);
  LogEvent(spdlog::level::info, "model loaded",
           {{"dir", model->model_dir},
            {"name", info.name},
            {"version", info.version},
            {"generation", model->generation}});
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

}  // namespace

void BlockServerSignals() {
  const sigset_t signals = ServerSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
}

int RunServer(const ServerConfig& config) {
  BlockServerSignals();  // before any thread starts, so all of them inherit the mask
  LogEvent(spdlog::level::info, "starting", ServerConfigToJson(config));

  ServerMetrics metrics;
  ModelHolder models;
  EngineConfig engine_config;
  engine_config.workers = config.workers;
  engine_config.queue_capacity = config.queue;
  engine_config.limits.max_bytes = config.max_image_bytes;
  engine_config.limits.max_pixels = config.max_image_pixels;
  InferenceEngine engine(engine_config, models, &metrics);
  engine.Start();

  // Listeners come up first and report not-ready until the model is loaded, so orchestrators
  // can tell "starting" from "dead".
  ObstacleDiscoveryService service(engine, models, metrics);
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  int grpc_port = 0;
  const std::string grpc_address = config.host + ":" + std::to_string(config.grpc_port);
  builder.AddListeningPort(grpc_address, grpc::InsecureServerCredentials(), &grpc_port);
  builder.SetMaxReceiveMessageSize(static_cast<int>(config.max_image_bytes + kGrpcMessageSlack));
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> grpc_server = builder.BuildAndStart();
  if (!grpc_server || grpc_port == 0) {
    LogEvent(spdlog::level::err, "cannot listen for gRPC", {{"address", grpc_address}});
    std::cerr << "tod_server: cannot listen for gRPC on " << grpc_address
              << " (port in use or not permitted)\n";
    return 1;
  }
  grpc::HealthCheckServiceInterface* health = grpc_server->GetHealthCheckService();
  // Register the service's own name too (grpc.health.v1 answers NOT_FOUND for unknown names);
  // SetServingStatus(bool) below then switches "" and this name together.
  health->SetServingStatus(tod::v1::ObstacleDiscovery::service_full_name(), false);
  health->SetServingStatus(false);

  HttpFrontendConfig http_config;
  http_config.limits = HttpLimitsFrom(config);
  http_config.retry_after_s = config.retry_after_s;
  http_config.io_threads = config.http_threads;
  HttpFrontend http(http_config, engine, models, metrics);
  if (Status bound = http.Bind(config.host, config.http_port); !bound.ok()) {
    LogEvent(spdlog::level::err, "cannot listen for HTTP", {{"error", bound.message()}});
    std::cerr << "tod_server: " << bound.message() << "\n";
    grpc_server->Shutdown();
    return 1;
  }
  http.Start();
  LogEvent(spdlog::level::info, "listening",
           {{"grpc", config.host + ":" + std::to_string(grpc_port)},
            {"http", config.host + ":" + std::to_string(http.port())}});

  if (Status loaded = models.Load(config.model_dir); !loaded.ok()) {
    LogEvent(spdlog::level::err, "model bundle refused", {{"error", loaded.ToString()}});
    std::cerr << "tod_server: cannot load model bundle " << config.model_dir << ": "
              << loaded.ToString() << "\n";
    http.Stop();
    grpc_server->Shutdown();
    return 1;
  }
  PublishModel(models, metrics);
  health->SetServingStatus(true);
  LogEvent(spdlog::level::info, "ready");

  const sigset_t signals = ServerSignals();
  for (;;) {
    int signal_number = 0;
    if (sigwait(&signals, &signal_number) != 0) continue;
    if (signal_number == SIGHUP) {
      LogEvent(spdlog::level::info, "reloading model", {{"dir", config.model_dir}});
      const Status reloaded = models.Reload();
      metrics.RecordReload(reloaded.ok());
      if (reloaded.ok()) {
        PublishModel(models, metrics);
      } else {
        LogEvent(spdlog::level::err, "reload refused; the previous model keeps serving",
                 {{"error", reloaded.ToString()}});
      }
      continue;
    }
    LogEvent(spdlog::level::info, "draining",
             {{"signal", signal_number == SIGTERM ? "SIGTERM" : "SIGINT"},
              {"queued", engine.queue_depth()},
              {"timeout_s", config.drain_timeout_s}});
    break;
  }

  // Drain: refuse new work and report not-serving, let admitted work finish, then close.
  engine.BeginDrain();
  health->SetServingStatus(false);
  const auto drain_deadline =
      std::chrono::steady_clock::now() +
      std::chrono::milliseconds(static_cast<long long>(config.drain_timeout_s * 1000));
  const bool drained = engine.WaitIdle(drain_deadline);
  if (!drained) {
    LogEvent(spdlog::level::warn, "drain timeout: unfinished requests are cancelled",
             {{"queued", engine.queue_depth()}});
  }
  grpc_server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  http.Stop();
  engine.Stop();
  LogEvent(spdlog::level::info, "stopped", {{"drained", drained}});
  spdlog::default_logger()->flush();
  return 0;
}

}  // namespace tod::server
