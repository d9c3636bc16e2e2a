#include "server/http_frontend.h"

#include <httplib.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <future>
#include <thread>

#include "server/detect_response.h"
#include "server/logging.h"
#include "server/status_mapping.h"

namespace tod::server {
namespace {

constexpr char kJson[] = "application/json";

void SetJsonError(httplib::Response& response, int http_status, const std::string& code,
                  const std::string& message) {
  response.status = http_status;
  const nlohmann::json body = {
      {"error", {{"code", code}, {"http_status", http_status}, {"message", message}}}};
  response.set_content(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), kJson);
}

// "image/png; charset=x" -> "image/png".
std::string MediaType(const std::string& content_type) {
  std::string type = content_type.substr(0, content_type.find(';'));
  type.erase(
      std::remove_if(type.begin(), type.end(), [](unsigned char c) { return std::isspace(c); }),
      type.end());
  std::transform(type.begin(), type.end(), type.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return type;
}

template <typename T>
Status ParseQueryNumber(const httplib::Request& request, const std::string& name, T* out) {
  if (!request.has_param(name.c_str())) return Status::Ok();
  const std::string text = request.get_param_value(name.c_str());
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), *out);
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size()) {
    return Status::InvalidArgument("query parameter " + name + "='" + text +
                                   "' is not a valid number");
  }
  return Status::Ok();
}

Status ParseDetectQuery(const httplib::Request& request, InferenceRequest* inference,
                        std::string* frame_id) {
  if (Status s = ParseQueryNumber(request, "max_proposals", &inference->options.max_proposals);
      !s.ok()) {
    return s;
  }
  if (Status s =
          ParseQueryNumber(request, "obstacle_threshold", &inference->options.obstacle_threshold);
      !s.ok()) {
    return s;
  }
  if (request.has_param("map")) {
    const std::string map = request.get_param_value("map");
    if (map == "none") {
      inference->encode_map_png = false;
    } else if (map == "png") {
      inference->encode_map_png = true;
    } else {
      return Status::InvalidArgument("query parameter map='" + map + "': expected png or none");
    }
  }
  long long timeout_ms = 0;
  if (Status s = ParseQueryNumber(request, "timeout_ms", &timeout_ms); !s.ok()) return s;
  if (timeout_ms < 0) return Status::InvalidArgument("query parameter timeout_ms must be >= 0");
  if (timeout_ms > 0) {
    inference->deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  }
  if (request.has_param("frame_id")) *frame_id = request.get_param_value("frame_id");
  return Status::Ok();
}

}  // namespace

HttpFrontend::HttpFrontend(HttpFrontendConfig config, InferenceEngine& engine,
                           const ModelHolder& models, ServerMetrics& metrics)
    : config_(config),
      engine_(engine),
      models_(models),
      metrics_(metrics),
      server_(std::make_unique<httplib::Server>()) {
  const int threads = config_.threads;
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  // httplib refuses bodies over this before our handler runs; leave room so that requests a bit
  // over the configured limit still reach the handler and get its explanatory 413.
  server_->set_payload_max_length(config_.max_image_bytes + (1u << 20));
  server_->set_keep_alive_max_count(100);
  server_->set_read_timeout(30, 0);
  server_->set_write_timeout(30, 0);

  server_->Post("/v1/detect", [this](const httplib::Request& request, httplib::Response& response) {
    HandleDetect(request, response, /*map_only=*/false);
  });
  server_->Post("/v1/probability-map",
                [this](const httplib::Request& request, httplib::Response& response) {
                  HandleDetect(request, response, /*map_only=*/true);
                });
  server_->Get("/v1/model", [this](const httplib::Request&, httplib::Response& response) {
    HandleModel(response);
  });
  server_->Get("/v2/health/live", [](const httplib::Request&, httplib::Response& response) {
    response.set_content(R"({"live":true})", kJson);
  });
  server_->Get("/v2/health/ready", [this](const httplib::Request&, httplib::Response& response) {
    const bool ready = engine_.Ready();
    response.status = ready ? 200 : 503;
    response.set_content(ready ? R"({"ready":true})" : R"({"ready":false})", kJson);
  });
  server_->Get("/metrics", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(metrics_.SerializeText(), "text/plain; version=0.0.4");
  });
  // Errors httplib produces itself (unknown path, body over its hard limit) get a JSON body too;
  // responses our handlers already filled are left alone.
  const httplib::Server::HandlerWithResponse on_error = [this](const httplib::Request& request,
                                                               httplib::Response& response) {
    if (!response.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    if (response.status == 413) {
      SetJsonError(response, 413, "RESOURCE_EXHAUSTED",
                   "request body is over the limit of " + std::to_string(config_.max_image_bytes) +
                       " bytes");
    } else if (response.status == 404) {
      SetJsonError(response, 404, "NOT_FOUND", "no such endpoint: " + request.path);
    } else {
      SetJsonError(response, response.status, "ERROR", "request failed");
    }
    return httplib::Server::HandlerResponse::Handled;
  };
  server_->set_error_handler(on_error);
}

HttpFrontend::~HttpFrontend() { Stop(); }

Status HttpFrontend::Bind(const std::string& host, int port) {
  if (port == 0) {
    port_ = server_->bind_to_any_port(host);
    if (port_ <= 0) return Status::Unavailable("http: cannot bind " + host + " to a free port");
  } else {
    if (!server_->bind_to_port(host, port)) {
      return Status::Unavailable("http: cannot bind " + host + ":" + std::to_string(port) +
                                 " (in use or not permitted)");
    }
    port_ = port;
  }
  return Status::Ok();
}

void HttpFrontend::Start() {
  listener_done_ = false;
  thread_ = std::thread([this] {
    server_->listen_after_bind();
    listener_done_ = true;
  });
}

void HttpFrontend::Stop() {
  if (!thread_.joinable()) return;
  // httplib's stop() does nothing until the listen loop runs: wait for it (or for its failure),
  // otherwise a Stop() right after Start() would leave the loop running and the join hanging.
  while (!server_->is_running() && !listener_done_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  server_->stop();
  thread_.join();
}

void HttpFrontend::HandleModel(httplib::Response& response) {
  const std::shared_ptr<const LoadedModel> model = models_.Current();
  if (!model) {
    SetJsonError(response, 503, "UNAVAILABLE", "model not loaded yet");
    metrics_.RecordRequest("http", "UNAVAILABLE", 0);
    return;
  }
  tod::v1::ModelInfo info;
  FillModelInfo(*model, &info);
  response.set_content(MessageToJson(info), kJson);
  metrics_.RecordRequest("http", "OK", 0);
}

void HttpFrontend::HandleDetect(const httplib::Request& request, httplib::Response& response,
                                bool map_only) {
  const auto started = std::chrono::steady_clock::now();
  const std::string request_id = std::string("h") + std::to_string(++request_counter_);
  std::string frame_id = request_id;
  auto finish_log = [&](const std::string& code, const std::string& error) {
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
            .count();
    metrics_.RecordRequest("http", code, ms / 1000.0);
    nlohmann::json fields = {{"id", request_id},
                             {"protocol", "http"},
                             {"path", request.path},
                             {"frame", frame_id},
                             {"peer", request.remote_addr},
                             {"bytes", request.body.size()},
                             {"status", response.status},
                             {"ms", ms}};
    if (!error.empty()) fields["error"] = error;
    LogEvent(error.empty() ? spdlog::level::info : spdlog::level::warn,
             map_only ? "probability-map" : "detect", fields);
  };

  const std::string media_type = MediaType(request.get_header_value("Content-Type"));
  if (media_type != "image/jpeg" && media_type != "image/png") {
    const std::string message =
        "Content-Type '" + request.get_header_value("Content-Type") +
        "' is not supported; send the raw image with Content-Type image/jpeg or image/png";
    SetJsonError(response, 415, "INVALID_ARGUMENT", message);
    metrics_.RecordRejection("bad_request");
    finish_log("INVALID_ARGUMENT", message);
    return;
  }
  InferenceRequest inference;
  inference.image = request.body;
  if (Status s = ParseDetectQuery(request, &inference, &frame_id); !s.ok()) {
    SetJsonError(response, 400, "INVALID_ARGUMENT", s.message());
    metrics_.RecordRejection("bad_request");
    finish_log("INVALID_ARGUMENT", s.message());
    return;
  }
  if (map_only) inference.encode_map_png = true;

  std::promise<InferenceResult> promise;
  std::future<InferenceResult> future = promise.get_future();
  engine_.Submit(inference,
                 [&promise](InferenceResult result) { promise.set_value(std::move(result)); });
  const InferenceResult result = future.get();  // the request body stays alive until here

  const std::string code = GrpcCodeName(ToGrpcCode(result.status.code()));
  if (!result.status.ok()) {
    const int http_status = HttpStatusFor(result.status, result.rejection);
    SetJsonError(response, http_status, code, result.status.message());
    if (result.rejection == Rejection::kQueueFull) {
      response.set_header("Retry-After", std::to_string(config_.retry_after_s));
    }
    finish_log(code, result.status.message());
    return;
  }
  if (map_only) {
    if (result.map_png.empty()) {
      SetJsonError(response, 500, "INTERNAL", "the pipeline produced no probability map");
      finish_log("INTERNAL", "no probability map");
      return;
    }
    response.set_content(result.map_png, "image/png");
    response.set_header("X-Model-Version", result.model->detector->info().version);
  } else {
    tod::v1::DetectResponse message;
    FillDetectResponse(result, frame_id, &message);
    response.set_content(MessageToJson(message), kJson);
  }
  response.status = 200;
  finish_log(code, "");
}

}  // namespace tod::server
