#include "server/grpc_frontend.h"

#include <optional>

#include "server/access_log.h"
#include "server/detect_response.h"
#include "server/grpc_call.h"
#include "server/grpc_messages.h"
#include "server/status_mapping.h"

namespace tod::server {
namespace {

// One frame at a time per stream: read, run, write, read the next. Responses therefore come back
// in request order, and a stream holds at most one queue slot.
class DetectStreamReactor final
    : public grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer> {
 public:
  DetectStreamReactor(ObstacleDiscoveryService& service, grpc::CallbackServerContext* context)
      : service_(service), context_(context) {
    StartRead(&request_);
  }

  // The whole stream is cancelled: the frame running (if any) stops at its next stage boundary.
  void OnCancel() override { cancellation_->Cancel(CallCancelReason(*context_)); }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client closed its side (or the call broke): nothing pending, done
      Finish(grpc::Status::OK);
      return;
    }
    response_.Clear();
    // Advance before submitting: the completion may run (and start the next read) at once.
    const long long index = frame_index_++;
    service_.SubmitFrame(
        context_, request_, std::to_string(index), cancellation_, camera_, &response_,
        [this, index](grpc::Status status) {
          if (!status.ok()) {
            Finish(grpc::Status(status.error_code(), std::string("frame ") + std::to_string(index) +
                                                         ": " + status.error_message()));
            return;
          }
          StartWrite(&response_);
        });
  }

  void OnWriteDone(bool ok) override {
    if (!ok) {
      Finish(grpc::Status(grpc::StatusCode::CANCELLED, "stream closed while writing"));
      return;
    }
    StartRead(&request_);
  }

  void OnDone() override { delete this; }  // the callback API's ownership model

 private:
  ObstacleDiscoveryService& service_;
  grpc::CallbackServerContext* const context_;
  grpc::ByteBuffer request_;
  grpc::ByteBuffer response_;
  long long frame_index_ = 0;
  const std::shared_ptr<Cancellation> cancellation_ = std::make_shared<Cancellation>();
  // A stream is one camera: its frames that name no camera_id share this horizon estimate,
  // which ends with the stream (fixed size, so a stream costs the same however long it runs).
  const std::shared_ptr<CameraTrack> camera_ = std::make_shared<CameraTrack>();
};

// A stream refused before its first read (no valid token).
class RefusedStreamReactor final
    : public grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer> {
 public:
  explicit RefusedStreamReactor(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace

ObstacleDiscoveryService::ObstacleDiscoveryService(InferenceEngine& engine,
                                                   const ModelHolder& models,
                                                   ServerMetrics& metrics,
                                                   std::shared_ptr<const TokenAuthenticator> auth)
    : engine_(engine), models_(models), metrics_(metrics), auth_(std::move(auth)) {}

std::optional<grpc::Status> ObstacleDiscoveryService::Refuse(
    const grpc::CallbackServerContext& context, const char* method) {
  return RefuseUnauthenticated(auth_.get(), context, method, metrics_);
}

std::string ObstacleDiscoveryService::NextRequestId() {
  return std::string("g") + std::to_string(++request_counter_);
}

void ObstacleDiscoveryService::SubmitFrame(grpc::CallbackServerContext* context,
                                           const grpc::ByteBuffer& request_bytes,
                                           const std::string& default_frame_id,
                                           std::shared_ptr<Cancellation> cancellation,
                                           std::shared_ptr<CameraTrack> stream_camera,
                                           grpc::ByteBuffer* response,
                                           std::function<void(grpc::Status)> done) {
  AccessRecord access;
  access.event = "detect";
  access.protocol = "grpc";
  access.id = NextRequestId();
  access.peer = context->peer();
  // Owned here (not by gRPC) so the image bytes live until the engine's completion has run.
  auto request = std::make_shared<tod::v1::DetectRequest>();
  if (Status parsed = ParseMessage(request_bytes, request.get()); !parsed.ok()) {
    access.frame = default_frame_id.empty() ? access.id : default_frame_id;
    access.bytes = request_bytes.Length();
    const grpc::Status status = RefuseUnparsed(*context, parsed, access);
    done(status);
    return;
  }
  const RequestOptions options = OptionsFromProto(request->options());
  InferenceRequest inference;
  inference.image = request->image();
  inference.model = request->model();
  inference.options = options.detect;
  inference.encode_map_png = options.encode_map_png;
  inference.deadline = SteadyDeadline(*context);
  inference.cancellation = std::move(cancellation);
  inference.camera_id = request->camera_id();
  inference.stream_camera = std::move(stream_camera);
  access.frame = !request->frame_id().empty() ? request->frame_id()
                 : !default_frame_id.empty()  ? default_frame_id
                                              : access.id;
  access.bytes = request->image().size();
  auto answer = [this, request, response, access, done = std::move(done)](InferenceResult result) {
    grpc::Status status = ToGrpcStatus(result.status);
    if (status.ok()) {
      tod::v1::DetectResponse message;
      FillDetectResponse(result, access.frame, &message);
      status = ToGrpcStatus(SerializeMessage(message, response));
    }
    LogFrame(access, status, result.total_ms,
             result.cancelled ? CancelReasonName(*result.cancelled) : nullptr);
    done(status);
  };
  engine_.Submit(inference, std::move(answer));
}

grpc::Status ObstacleDiscoveryService::RefuseUnparsed(const grpc::CallbackServerContext& context,
                                                      const Status& parsed,
                                                      const AccessRecord& access) {
  if (context.IsCancelled()) {  // the request never arrived whole: not a malformed one
    const grpc::Status status(grpc::StatusCode::CANCELLED,
                              "the client cancelled the call before its request arrived");
    LogFrame(access, status, 0, CancelReasonName(CancelReason::kClientCancelled));
    return status;
  }
  metrics_.RecordRejection("bad_request");
  const grpc::Status status = ToGrpcStatus(parsed);
  LogFrame(access, status, 0);
  return status;
}

void ObstacleDiscoveryService::LogFrame(AccessRecord access, const grpc::Status& status, double ms,
                                        const char* cancelled) {
  access.code = GrpcCodeName(status.error_code());
  access.status = access.code;
  access.ms = ms;
  if (!status.ok()) access.error = status.error_message();
  access.cancelled = cancelled;
  LogAccess(access, metrics_);
}

grpc::ServerUnaryReactor* ObstacleDiscoveryService::Detect(grpc::CallbackServerContext* context,
                                                           const grpc::ByteBuffer* request,
                                                           grpc::ByteBuffer* response) {
  if (std::optional<grpc::Status> refused = Refuse(*context, "Detect")) {
    grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
    reactor->Finish(*refused);
    return reactor;
  }
  auto cancellation = std::make_shared<Cancellation>();
  auto* reactor = new CancellableUnaryReactor(*context, cancellation);  // deletes itself in OnDone
  SubmitFrame(context, *request, "", std::move(cancellation), nullptr, response,
              [reactor](grpc::Status status) { reactor->Finish(status); });
  return reactor;
}

grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* ObstacleDiscoveryService::DetectStream(
    grpc::CallbackServerContext* context) {
  // Both reactors delete themselves in OnDone.
  if (std::optional<grpc::Status> refused = Refuse(*context, "DetectStream")) {
    return new RefusedStreamReactor(*refused);
  }
  return new DetectStreamReactor(*this, context);
}

grpc::ServerUnaryReactor* ObstacleDiscoveryService::GetModelInfo(
    grpc::CallbackServerContext* context, const grpc::ByteBuffer* request,
    grpc::ByteBuffer* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  if (std::optional<grpc::Status> refused = Refuse(*context, "GetModelInfo")) {
    reactor->Finish(*refused);
    return reactor;
  }
  grpc::Status status;
  tod::v1::GetModelInfoRequest parsed;
  if (Status valid = ParseMessage(*request, &parsed); !valid.ok()) {
    status = ToGrpcStatus(valid);
  } else if (models_.empty()) {
    status = grpc::Status(grpc::StatusCode::UNAVAILABLE, "model not loaded yet");
  } else if (const std::shared_ptr<const LoadedModel> model = models_.Find(parsed.model());
             !model) {
    status = grpc::Status(grpc::StatusCode::NOT_FOUND, "unknown model '" + parsed.model() + "'");
  } else {
    tod::v1::ModelInfo info;
    FillModelInfo(*model, &info);
    status = ToGrpcStatus(SerializeMessage(info, response));
  }
  metrics_.RecordRequest("grpc", GrpcCodeName(status.error_code()), 0);
  reactor->Finish(status);
  return reactor;
}

}  // namespace tod::server
