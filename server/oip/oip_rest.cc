#include "server/oip/oip_rest.h"

#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "server/access_log.h"
#include "server/oip/oip_errors.h"
#include "server/oip/oip_model.h"
#include "server/oip/oip_path.h"
#include "server/status_mapping.h"

namespace tod::server::oip {
namespace {

using http::beast_http::field;
using http::beast_http::verb;
using nlohmann::json;

constexpr const char* kJson = kJsonType;

std::string CodeName(const Status& status) { return GrpcCodeName(ToGrpcCode(status.code())); }

http::Response WrongMethod(std::string_view path, const char* allowed) {
  http::Response response = OipError(405, std::string(path) + " allows " + allowed + " only");
  response.set(field::allow, allowed);
  return response;
}

// How an infer request ended: its answer, the gRPC code name the metrics count and the access
// log's error (empty: none).
struct Outcome {
  http::Response response;
  std::string code;
  std::string error;
};

Outcome Refusal(const Status& status) {
  return {OipError(status), CodeName(status), status.message()};
}

}  // namespace

bool NeedsToken(std::string_view path) {
  // /v2/repository/... checks the admin tokens itself (oip_repository.h).
  return path == "/v2" || (path.starts_with("/v2/") && !path.starts_with("/v2/health/") &&
                           !path.starts_with("/v2/repository/"));
}

OipRestApi::OipRestApi(int retry_after_s, size_t max_image_bytes, InferenceEngine& engine,
                       const ModelHolder& models, ServerMetrics& metrics,
                       std::atomic<uint64_t>& counter)
    : retry_after_s_(retry_after_s),
      limits_{.max_image_bytes = max_image_bytes},
      engine_(engine),
      models_(models),
      metrics_(metrics),
      counter_(counter) {}

void OipRestApi::AddRoutes(http::Router* router) const {
  router->Add(verb::get, "/v2", [](http::IncomingRequest, http::Responder respond) {
    respond(http::ContentResponse(Dump(ServerMetadata()), kJson));
  });
  // Every model path goes to one handler per method, which parses the rest of the path.
  router->AddPrefix(verb::get, std::string(kModelsPrefix),
                    [this](http::IncomingRequest request, http::Responder respond) {
                      HandleGet(request, respond);
                    });
  router->AddPrefix(verb::post, std::string(kModelsPrefix),
                    [this](http::IncomingRequest request, http::Responder respond) {
                      Infer(std::move(request), std::move(respond));
                    });
}

void OipRestApi::HandleGet(const http::IncomingRequest& request,
                           const http::Responder& respond) const {
  const std::string_view target = http::TargetPath(request.message.target());
  const std::optional<ModelPath> path = ParseModelPath(target);
  if (!path) {
    respond(OipError(404, "no such endpoint: " + std::string(target)));
    return;
  }
  if (path->action == ModelAction::kInfer) {
    respond(WrongMethod(target, "POST"));
    return;
  }
  const Result<std::shared_ptr<const LoadedModel>> model =
      ResolveModel(models_, path->name, path->version);
  if (path->action == ModelAction::kReady) {
    // A probe: answered, not counted as a request.
    if (!model.ok()) {
      respond(OipError(model.status()));
      return;
    }
    const bool ready = engine_.Ready();
    respond(http::ContentResponse(Dump({{"name", path->name}, {"ready", ready}}), kJson,
                                  ready ? 200 : 503));
    return;
  }
  if (!model.ok()) {
    metrics_.RecordRequest("http", CodeName(model.status()), 0);
    respond(OipError(model.status()));
    return;
  }
  metrics_.RecordRequest("http", "OK", 0);
  respond(http::ContentResponse(Dump(ModelMetadata((*model)->detector->info())), kJson));
}

void OipRestApi::Infer(http::IncomingRequest incoming, http::Responder respond) const {
  // The request (whose body the parsed image may view) and its parse live until the answer.
  struct Call {
    http::IncomingRequest request;
    InferRequest parsed;
  };
  auto call = std::make_shared<Call>(Call{std::move(incoming), {}});
  const http::Request& message = call->request.message;
  const auto started = std::chrono::steady_clock::now();
  const std::string request_id = "h" + std::to_string(++counter_);
  // Logs the request's line (and counts it), then sends its answer.
  auto finish = [this, call, respond, started, request_id](Outcome outcome,
                                                           const std::string& frame_id) {
    AccessRecord access;
    access.event = "infer";
    access.protocol = "http";
    access.id = request_id;
    access.path = std::string(http::TargetPath(call->request.message.target()));
    access.frame = frame_id;
    access.peer = call->request.peer;
    access.bytes = call->request.message.body().size();
    access.status = outcome.response.result_int();
    access.code = outcome.code;
    access.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
            .count();
    if (!outcome.error.empty()) access.error = outcome.error;
    LogAccess(access, metrics_);
    respond(std::move(outcome.response));
  };
  std::string frame_id = request_id;
  const auto refuse = [&](const Status& status) {
    metrics_.RecordRejection(RejectionName(status.code() == StatusCode::kResourceExhausted
                                               ? Rejection::kTooLarge
                                               : Rejection::kBadRequest));
    finish(Refusal(status), frame_id);
  };

  const std::string_view target = http::TargetPath(message.target());
  const std::optional<ModelPath> path = ParseModelPath(target);
  if (!path) {
    finish(Refusal(Status::NotFound("no such endpoint: " + std::string(target))), frame_id);
    return;
  }
  if (path->action != ModelAction::kInfer) {
    finish({WrongMethod(target, "GET"), "INVALID_ARGUMENT", "POST on a GET endpoint"}, frame_id);
    return;
  }
  if (const Result<std::shared_ptr<const LoadedModel>> model =
          ResolveModel(models_, path->name, path->version);
      !model.ok()) {
    finish(Refusal(model.status()), frame_id);
    return;
  }
  std::optional<std::string_view> header_length;
  if (message.count(kHeaderLengthField) > 1) {
    refuse(Status::InvalidArgument(std::string(kHeaderLengthField) + " is given more than once"));
    return;
  }
  if (const auto it = message.find(kHeaderLengthField); it != message.end()) {
    header_length = it->value();
  }
  Result<InferRequest> parsed = ParseInferRequest(message.body(), header_length, limits_);
  if (!parsed.ok()) {
    refuse(parsed.status());
    return;
  }
  call->parsed = std::move(*parsed);
  const InferRequest& request = call->parsed;
  if (Status s = CheckOutputs(request); !s.ok()) {
    refuse(s);
    return;
  }

  InferenceRequest inference;
  inference.image = request.image();
  inference.cancellation = call->request.client_gone;
  inference.encode_map_png = WantsMap(request);
  if (request.id) frame_id = *request.id;  // frame_id, when given, overrides it
  if (Status s = ApplyOptions(request, &inference, &frame_id); !s.ok()) {
    refuse(s);
    return;
  }
  inference.model = path->name;

  // Runs on a worker (or inline when refused at admission); never blocks an I/O thread.
  engine_.Submit(inference, [this, call, finish, frame_id](InferenceResult result) {
    if (!result.status.ok()) {
      const Status& status = result.status;
      http::Response response = OipError(HttpStatusFor(status, result.rejection), status.message());
      if (result.rejection == Rejection::kQueueFull) {
        response.set(field::retry_after, std::to_string(retry_after_s_));
      }
      finish({std::move(response), CodeName(status), status.message()}, frame_id);
      return;
    }
    const Result<std::vector<OutputTensor>> outputs = BuildOutputs(call->parsed, result);
    if (!outputs.ok()) {
      finish({OipError(500, outputs.status().message()), "INTERNAL", outputs.status().message()},
             frame_id);
      return;
    }
    EncodedResponse encoded =
        EncodeInferResponse(ResponseHead(call->parsed, result, frame_id), *outputs);
    http::Response response = http::ContentResponse(
        std::move(encoded.body), encoded.header_length ? "application/octet-stream" : kJson);
    if (encoded.header_length) {
      response.set(kHeaderLengthField, std::to_string(*encoded.header_length));
    }
    finish({std::move(response), "OK", ""}, frame_id);
  });
}

}  // namespace tod::server::oip
