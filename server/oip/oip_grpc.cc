#include "server/oip/oip_grpc.h"

#include <chrono>
#include <optional>

#include "server/access_log.h"
#include "server/core/rejection.h"
#include "server/grpc_call.h"
#include "server/grpc_messages.h"
#include "server/oip/oip_grpc_messages.h"
#include "server/oip/oip_model.h"
#include "server/status_mapping.h"

namespace tod::server::oip {
namespace {

constexpr char kInferPath[] = "/inference.GRPCInferenceService/ModelInfer";

std::optional<std::string_view> VersionOf(const std::string& version) {
  if (version.empty()) return std::nullopt;
  return version;
}

// The earlier of the request's own deadline (timeout_ms) and the call's.
void ApplyCallDeadline(const grpc::CallbackServerContext& context, InferenceRequest* inference) {
  const auto call_deadline = SteadyDeadline(context);
  if (call_deadline && (!inference->deadline || *call_deadline < *inference->deadline)) {
    inference->deadline = call_deadline;
  }
}

}  // namespace

OipGrpcService::OipGrpcService(InferenceEngine& engine, const ModelHolder& models,
                               ServerMetrics& metrics, size_t max_image_bytes,
                               std::function<std::string()> next_request_id,
                               std::shared_ptr<const TokenAuthenticator> auth)
    : engine_(engine),
      models_(models),
      metrics_(metrics),
      limits_{.max_image_bytes = max_image_bytes},
      next_request_id_(std::move(next_request_id)),
      auth_(std::move(auth)) {}

grpc::ServerUnaryReactor* OipGrpcService::Answer(grpc::CallbackServerContext* context,
                                                 grpc::Status status) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  reactor->Finish(status);
  return reactor;
}

grpc::ServerUnaryReactor* OipGrpcService::ServerLive(grpc::CallbackServerContext* context,
                                                     const inference::ServerLiveRequest*,
                                                     inference::ServerLiveResponse* response) {
  response->set_live(true);
  return Answer(context, grpc::Status::OK);
}

grpc::ServerUnaryReactor* OipGrpcService::ServerReady(grpc::CallbackServerContext* context,
                                                      const inference::ServerReadyRequest*,
                                                      inference::ServerReadyResponse* response) {
  response->set_ready(engine_.Ready());
  return Answer(context, grpc::Status::OK);
}

grpc::ServerUnaryReactor* OipGrpcService::ModelReady(grpc::CallbackServerContext* context,
                                                     const inference::ModelReadyRequest* request,
                                                     inference::ModelReadyResponse* response) {
  if (auto refused = RefuseUnauthenticated(auth_.get(), *context, "ModelReady", metrics_)) {
    return Answer(context, *refused);
  }
  // A probe: answered, not counted as a request (as GET /v2/models/{name}/ready).
  const auto model = ResolveModel(models_, request->name(), VersionOf(request->version()));
  if (!model.ok()) return Answer(context, ToGrpcStatus(model.status()));
  response->set_ready(engine_.Ready());
  return Answer(context, grpc::Status::OK);
}

grpc::ServerUnaryReactor* OipGrpcService::ServerMetadata(
    grpc::CallbackServerContext* context, const inference::ServerMetadataRequest*,
    inference::ServerMetadataResponse* response) {
  if (auto refused = RefuseUnauthenticated(auth_.get(), *context, "ServerMetadata", metrics_)) {
    return Answer(context, *refused);
  }
  *response = ToServerMetadataResponse(oip::ServerMetadata());
  return Answer(context, grpc::Status::OK);
}

grpc::ServerUnaryReactor* OipGrpcService::ModelMetadata(
    grpc::CallbackServerContext* context, const inference::ModelMetadataRequest* request,
    inference::ModelMetadataResponse* response) {
  if (auto refused = RefuseUnauthenticated(auth_.get(), *context, "ModelMetadata", metrics_)) {
    return Answer(context, *refused);
  }
  const auto model = ResolveModel(models_, request->name(), VersionOf(request->version()));
  const grpc::Status status = model.ok() ? grpc::Status::OK : ToGrpcStatus(model.status());
  if (model.ok())
    *response = ToModelMetadataResponse(oip::ModelMetadata((*model)->detector->info()));
  metrics_.RecordRequest("grpc", GrpcCodeName(status.error_code()), 0);
  return Answer(context, status);
}

grpc::ServerUnaryReactor* OipGrpcService::ModelInfer(grpc::CallbackServerContext* context,
                                                     const grpc::ByteBuffer* request_bytes,
                                                     grpc::ByteBuffer* response) {
  if (auto refused = RefuseUnauthenticated(auth_.get(), *context, "ModelInfer", metrics_)) {
    return Answer(context, *refused);
  }
  // The message (whose bytes the parsed image views) and its parse live until the answer.
  struct Call {
    inference::ModelInferRequest message;
    InferRequest parsed;
  };
  auto call = std::make_shared<Call>();
  auto cancellation = std::make_shared<Cancellation>();
  auto* reactor = new CancellableUnaryReactor(*context, cancellation);  // deletes itself in OnDone

  AccessRecord access;
  access.event = "infer";
  access.protocol = "grpc";
  access.id = next_request_id_();
  access.path = kInferPath;
  access.frame = access.id;
  access.peer = context->peer();
  access.bytes = request_bytes->Length();
  const auto started = std::chrono::steady_clock::now();
  // Logs the call's line (and counts it), then finishes it.
  auto finish = [this, reactor, started](AccessRecord record, const grpc::Status& status,
                                         const char* cancelled = nullptr) {
    record.code = GrpcCodeName(status.error_code());
    record.status = record.code;
    record.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
            .count();
    if (!status.ok()) record.error = status.error_message();
    record.cancelled = cancelled;
    LogAccess(record, metrics_);
    reactor->Finish(status);
  };
  const auto refuse = [&](const Status& status) {
    metrics_.RecordRejection(RejectionName(status.code() == StatusCode::kResourceExhausted
                                               ? Rejection::kTooLarge
                                               : Rejection::kBadRequest));
    finish(access, ToGrpcStatus(status));
  };

  if (Status parsed = ParseMessage(*request_bytes, &call->message); !parsed.ok()) {
    if (context->IsCancelled()) {  // the request never arrived whole: not a malformed one
      finish(access,
             grpc::Status(grpc::StatusCode::CANCELLED,
                          "the client cancelled the call before its request arrived"),
             CancelReasonName(CancelReason::kClientCancelled));
    } else {
      refuse(parsed);
    }
    return reactor;
  }
  const inference::ModelInferRequest& message = call->message;
  if (const auto model =
          ResolveModel(models_, message.model_name(), VersionOf(message.model_version()));
      !model.ok()) {
    finish(access, ToGrpcStatus(model.status()));
    return reactor;
  }
  Result<InferRequest> parsed = FromModelInferRequest(message, limits_);
  if (!parsed.ok()) {
    refuse(parsed.status());
    return reactor;
  }
  call->parsed = std::move(*parsed);
  const InferRequest& request = call->parsed;
  if (Status s = CheckOutputs(request); !s.ok()) {
    refuse(s);
    return reactor;
  }
  InferenceRequest inference;
  inference.image = request.image();
  inference.cancellation = std::move(cancellation);
  inference.encode_map_png = WantsMap(request);
  if (request.id) access.frame = *request.id;  // frame_id, when given, overrides it
  if (Status s = ApplyOptions(request, &inference, &access.frame); !s.ok()) {
    refuse(s);
    return reactor;
  }
  inference.model = message.model_name();
  ApplyCallDeadline(*context, &inference);
  access.bytes = request.image().size();

  engine_.Submit(inference, [call, response, access, finish](InferenceResult result) {
    grpc::Status status = ToGrpcStatus(result.status);
    if (status.ok()) {
      const Result<std::vector<OutputTensor>> outputs = BuildOutputs(call->parsed, result);
      status = !outputs.ok() ? ToGrpcStatus(outputs.status())
                             : ToGrpcStatus(SerializeMessage(
                                   ToModelInferResponse(
                                       ResponseHead(call->parsed, result, access.frame), *outputs),
                                   response));
    }
    finish(access, status, result.cancelled ? CancelReasonName(*result.cancelled) : nullptr);
  });
  return reactor;
}

}  // namespace tod::server::oip
