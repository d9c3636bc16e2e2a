#include "server/http_frontend.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <optional>

#include "proto/json/message_json.h"
#include "server/access_log.h"
#include "server/detect_response.h"
#include "server/http/http_server.h"
#include "server/http/query_string.h"
#include "server/logging.h"
#include "server/oip/oip_repository.h"
#include "server/oip/oip_rest.h"
#include "server/rest_options.h"
#include "server/status_mapping.h"

namespace tod::server {
namespace {

using http::beast_http::field;
using http::beast_http::verb;

constexpr char kJson[] = "application/json";

// "image/png; charset=x" -> "image/png".
std::string MediaType(std::string_view content_type) {
  std::string type(content_type.substr(0, content_type.find(';')));
  type.erase(
      std::remove_if(type.begin(), type.end(), [](unsigned char c) { return std::isspace(c); }),
      type.end());
  std::transform(type.begin(), type.end(), type.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return type;
}

// How one REST detection request ended: its answer, the gRPC code name the metrics count, and
// the error its access-log line shows (empty: none).
struct Outcome {
  http::Response response;
  std::string code;
  std::string error;
};

// The body is an image (by its Content-Type) and the query is valid: fills `inference` and
// `frame_id` (when the query names one); otherwise the refusal (415 or 400).
std::optional<Outcome> ParseRequest(const http::IncomingRequest& request,
                                    InferenceRequest* inference, std::string* frame_id) {
  const std::string_view content_type = request.message[field::content_type];
  const std::string media_type = MediaType(content_type);
  if (media_type != "image/jpeg" && media_type != "image/png" && media_type != "image/webp") {
    const std::string message = "Content-Type '" + std::string(content_type) +
                                "' is not supported; send the raw image with Content-Type "
                                "image/jpeg, image/png or image/webp";
    return Outcome{http::JsonErrorResponse(415, "INVALID_ARGUMENT", message), "INVALID_ARGUMENT",
                   message};
  }
  inference->image = request.message.body();
  inference->cancellation = request.client_gone;
  if (Status s = ParseDetectQuery(http::ParseQuery(request.message.target()), inference, frame_id);
      !s.ok()) {
    return Outcome{http::JsonErrorResponse(400, "INVALID_ARGUMENT", s.message()),
                   "INVALID_ARGUMENT", s.message()};
  }
  return std::nullopt;
}

// The access-log record of a detection request that ended with `outcome`.
AccessRecord RestAccess(const http::IncomingRequest& request, const std::string& request_id,
                        bool map_only, const std::string& frame_id, const Outcome& outcome,
                        std::chrono::steady_clock::time_point started) {
  AccessRecord access;
  access.event = map_only ? "probability-map" : "detect";
  access.protocol = "http";
  access.id = request_id;
  access.path = std::string(http::TargetPath(request.message.target()));
  access.frame = frame_id;
  access.peer = request.peer;
  access.bytes = request.message.body().size();
  access.status = outcome.response.result_int();
  access.code = outcome.code;
  access.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
  if (!outcome.error.empty()) access.error = outcome.error;
  return access;
}

}  // namespace

// The REST handlers, stateless apart from the references they answer from.
class RestApi {
 public:
  RestApi(const HttpFrontendConfig& config, InferenceEngine& engine, ModelHolder& models,
          ServerMetrics& metrics, std::atomic<uint64_t>& counter)
      : config_(config),
        engine_(engine),
        models_(models),
        metrics_(metrics),
        counter_(counter),
        oip_(config.retry_after_s, config.limits.max_body_bytes, engine, models, metrics, counter),
        repository_(std::make_unique<oip::OipRepositoryApi>(models, config.admin,
                                                            config.on_models_changed)) {}

  http::Router Routes() const {
    http::Router router;
    router.Add(verb::post, "/v1/detect", [this](http::IncomingRequest request, http::Responder r) {
      Detect(std::move(request), std::move(r), /*map_only=*/false);
    });
    router.Add(verb::post, "/v1/probability-map",
               [this](http::IncomingRequest request, http::Responder r) {
                 Detect(std::move(request), std::move(r), /*map_only=*/true);
               });
    router.Add(verb::get, "/v1/model", [this](http::IncomingRequest request, http::Responder r) {
      r(Model(request));
    });
    router.Add(verb::get, "/v2/health/live", [](http::IncomingRequest, http::Responder r) {
      r(http::ContentResponse(R"({"live":true})", kJson));
    });
    router.Add(verb::get, "/v2/health/ready", [this](http::IncomingRequest, http::Responder r) {
      const bool ready = engine_.Ready();
      r(http::ContentResponse(ready ? R"({"ready":true})" : R"({"ready":false})", kJson,
                              ready ? 200 : 503));
    });
    router.Add(verb::get, "/metrics", [this](http::IncomingRequest, http::Responder r) {
      r(http::ContentResponse(metrics_.SerializeText(), "text/plain; version=0.0.4"));
    });
    oip_.AddRoutes(&router);          // the Open Inference Protocol: /v2, /v2/models/...
    repository_->AddRoutes(&router);  // and its repository extension: /v2/repository/...
    return router;
  }

 private:
  // GET /v1/model[?model=NAME]: the default model's info, or the named one's.
  http::Response Model(const http::IncomingRequest& request) const {
    if (models_.empty()) {
      metrics_.RecordRequest("http", "UNAVAILABLE", 0);
      return http::JsonErrorResponse(503, "UNAVAILABLE", "model not loaded yet");
    }
    const QueryParams query = http::ParseQuery(request.message.target());
    const auto named = query.find("model");
    const std::string name = named == query.end() ? "" : named->second;
    const std::shared_ptr<const LoadedModel> model = models_.Find(name);
    if (!model) {
      metrics_.RecordRequest("http", "NOT_FOUND", 0);
      return http::JsonErrorResponse(404, "NOT_FOUND", "unknown model '" + name + "'");
    }
    tod::v1::ModelInfo info;
    FillModelInfo(*model, &info);
    metrics_.RecordRequest("http", "OK", 0);
    return http::ContentResponse(proto::MessageToJson(info), kJson);
  }

  void Detect(http::IncomingRequest incoming, http::Responder respond, bool map_only) const {
    // The request (and so the image bytes the engine reads) lives until the answer is built.
    auto request = std::make_shared<const http::IncomingRequest>(std::move(incoming));
    const auto started = std::chrono::steady_clock::now();
    const std::string request_id = "h" + std::to_string(++counter_);
    // Logs the request's line, then sends its answer.
    auto finish = [this, started, request_id, map_only, request, respond](
                      Outcome outcome, const std::string& frame_id) {
      LogAccess(RestAccess(*request, request_id, map_only, frame_id, outcome, started), metrics_);
      respond(std::move(outcome.response));
    };

    InferenceRequest inference;
    std::string frame_id = request_id;
    if (std::optional<Outcome> refused = ParseRequest(*request, &inference, &frame_id)) {
      metrics_.RecordRejection("bad_request");
      finish(std::move(*refused), frame_id);
      return;
    }
    if (map_only) inference.encode_map_png = true;

    // Runs on a worker (or inline when refused at admission); never blocks an I/O thread.
    engine_.Submit(inference, [this, finish, frame_id, map_only](InferenceResult result) {
      finish(Answer(std::move(result), frame_id, map_only), frame_id);
    });
  }

  // The REST answer to an engine result: the error (with Retry-After when the queue was full),
  // the map as PNG, or the DetectResponse as JSON.
  Outcome Answer(InferenceResult result, const std::string& frame_id, bool map_only) const {
    const std::string code = GrpcCodeName(ToGrpcCode(result.status.code()));
    if (!result.status.ok()) {
      http::Response response = http::JsonErrorResponse(
          HttpStatusFor(result.status, result.rejection), code, result.status.message());
      if (result.rejection == Rejection::kQueueFull) {
        response.set(field::retry_after, std::to_string(config_.retry_after_s));
      }
      return {std::move(response), code, result.status.message()};
    }
    if (map_only) {
      if (result.map_png.empty()) {
        return {http::JsonErrorResponse(500, "INTERNAL", "the pipeline produced no map"),
                "INTERNAL", "no probability map"};
      }
      http::Response response = http::ContentResponse(std::move(result.map_png), "image/png");
      response.set("X-Model-Version", result.model->detector->info().version);
      return {std::move(response), code, ""};
    }
    tod::v1::DetectResponse message;
    FillDetectResponse(result, frame_id, &message);
    return {http::ContentResponse(proto::MessageToJson(message), kJson), code, ""};
  }

  const HttpFrontendConfig& config_;
  InferenceEngine& engine_;
  const ModelHolder& models_;
  ServerMetrics& metrics_;
  std::atomic<uint64_t>& counter_;
  const oip::OipRestApi oip_;
  const std::unique_ptr<oip::OipRepositoryApi> repository_;
};

HttpFrontend::HttpFrontend(HttpFrontendConfig config, InferenceEngine& engine, ModelHolder& models,
                           ServerMetrics& metrics)
    : config_(config),
      engine_(engine),
      models_(models),
      metrics_(metrics),
      api_(std::make_unique<RestApi>(config_, engine_, models_, metrics_, request_counter_)) {
  http::HttpObserver observer;
  observer.on_refusal = [this](const http::Refusal& refusal) {
    metrics_.RecordHttpRefusal(http::RefusalReasonName(refusal.reason));
    LogEvent(spdlog::level::warn, "http refused",
             {{"protocol", "http"},
              {"reason", http::RefusalReasonName(refusal.reason)},
              {"status", http::RefusalHttpStatus(refusal.reason)},
              {"peer", refusal.peer},
              {"target", refusal.target.substr(0, 256)},
              {"error", refusal.message}});
  };
  observer.on_open_connections = [this](int open) { metrics_.SetHttpConnections(open); };
  http::HttpServerOptions options;
  options.limits = config_.limits;
  options.io_threads = config_.io_threads;
  options.retry_after_s = config_.retry_after_s;
  options.tls = config_.tls;
  if (config_.auth) {
    options.authorizer = [auth = config_.auth](const http::Request& header) {
      // Probes (/v2/health/*) and scrapers (/metrics) stay open; both APIs need a token.
      const std::string_view path = http::TargetPath(header.target());
      if (!path.starts_with("/v1/") && !oip::NeedsToken(path)) {
        return std::optional<std::string>();
      }
      return auth->Check(header[field::authorization]);
    };
  }
  server_ =
      std::make_unique<http::HttpServer>(std::move(options), api_->Routes(), std::move(observer));
}

HttpFrontend::~HttpFrontend() { Stop(); }

Status HttpFrontend::Bind(const std::string& host, int port) { return server_->Bind(host, port); }

int HttpFrontend::port() const { return server_->port(); }

void HttpFrontend::Start() { server_->Start(); }

void HttpFrontend::Stop(std::chrono::milliseconds grace) { server_->Stop(grace); }

}  // namespace tod::server
