#include "server/grpc_frontend.h"

#include <chrono>
#include <optional>

#include "server/detect_response.h"
#include "server/logging.h"
#include "server/status_mapping.h"

namespace tod::server {
namespace {

// gRPC reports the client's deadline on the system clock; the engine works on the steady clock.
std::optional<std::chrono::steady_clock::time_point> SteadyDeadline(
    const grpc::CallbackServerContext& context) {
  const auto deadline = context.deadline();
  if (deadline >= std::chrono::system_clock::time_point::max() - std::chrono::hours(24 * 365)) {
    return std::nullopt;  // no deadline set
  }
  const auto remaining = deadline - std::chrono::system_clock::now();
  return std::chrono::steady_clock::now() +
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(remaining);
}

// One frame at a time per stream: read, run, write, read the next. Responses therefore come back
// in request order, and a stream holds at most one queue slot.
class DetectStreamReactor final
    : public grpc::ServerBidiReactor<tod::v1::DetectRequest, tod::v1::DetectResponse> {
 public:
  DetectStreamReactor(ObstacleDiscoveryService& service, grpc::CallbackServerContext* context)
      : service_(service), context_(context) {
    StartRead(&request_);
  }

  void OnReadDone(bool ok) override {
    if (!ok) {  // the client closed its side (or the call broke): nothing pending, done
      Finish(grpc::Status::OK);
      return;
    }
    response_.Clear();
    // Advance before submitting: the completion may run (and start the next read) at once.
    const long long index = frame_index_++;
    service_.SubmitFrame(
        context_, request_, std::to_string(index), &response_, [this, index](grpc::Status status) {
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
  tod::v1::DetectRequest request_;
  tod::v1::DetectResponse response_;
  long long frame_index_ = 0;
};

}  // namespace

ObstacleDiscoveryService::ObstacleDiscoveryService(InferenceEngine& engine,
                                                   const ModelHolder& models,
                                                   ServerMetrics& metrics)
    : engine_(engine), models_(models), metrics_(metrics) {}

std::string ObstacleDiscoveryService::NextRequestId() {
  return std::string("g") + std::to_string(++request_counter_);
}

void ObstacleDiscoveryService::SubmitFrame(grpc::CallbackServerContext* context,
                                           const tod::v1::DetectRequest& request,
                                           const std::string& default_frame_id,
                                           tod::v1::DetectResponse* response,
                                           std::function<void(grpc::Status)> done) {
  const RequestOptions options = OptionsFromProto(request.options());
  InferenceRequest inference;
  inference.image = request.image();
  inference.options = options.detect;
  inference.encode_map_png = options.encode_map_png;
  inference.deadline = SteadyDeadline(*context);
  const std::string request_id = NextRequestId();
  const std::string frame_id = !request.frame_id().empty() ? request.frame_id()
                               : !default_frame_id.empty() ? default_frame_id
                                                           : request_id;
  const size_t bytes = request.image().size();
  const std::string peer = context->peer();
  engine_.Submit(inference, [this, response, frame_id, request_id, bytes, peer,
                             done = std::move(done)](InferenceResult result) {
    const grpc::Status status = ToGrpcStatus(result.status);
    if (status.ok()) FillDetectResponse(result, frame_id, response);
    const std::string code = GrpcCodeName(status.error_code());
    metrics_.RecordRequest("grpc", code, result.total_ms / 1000.0);
    nlohmann::json fields = {{"id", request_id},     {"protocol", "grpc"}, {"frame", frame_id},
                             {"peer", peer},         {"bytes", bytes},     {"status", code},
                             {"ms", result.total_ms}};
    if (!status.ok()) fields["error"] = status.error_message();
    LogEvent(status.ok() ? spdlog::level::info : spdlog::level::warn, "detect", fields);
    done(status);
  });
}

grpc::ServerUnaryReactor* ObstacleDiscoveryService::Detect(grpc::CallbackServerContext* context,
                                                           const tod::v1::DetectRequest* request,
                                                           tod::v1::DetectResponse* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  SubmitFrame(context, *request, "", response,
              [reactor](grpc::Status status) { reactor->Finish(status); });
  return reactor;
}

grpc::ServerBidiReactor<tod::v1::DetectRequest, tod::v1::DetectResponse>*
ObstacleDiscoveryService::DetectStream(grpc::CallbackServerContext* context) {
  return new DetectStreamReactor(*this, context);  // deletes itself in OnDone
}

grpc::ServerUnaryReactor* ObstacleDiscoveryService::GetModelInfo(
    grpc::CallbackServerContext* context, const tod::v1::GetModelInfoRequest* /*request*/,
    tod::v1::ModelInfo* response) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  const std::shared_ptr<const LoadedModel> model = models_.Current();
  if (!model) {
    reactor->Finish(grpc::Status(grpc::StatusCode::UNAVAILABLE, "model not loaded yet"));
  } else {
    FillModelInfo(*model, response);
    reactor->Finish(grpc::Status::OK);
  }
  metrics_.RecordRequest("grpc", model ? "OK" : "UNAVAILABLE", 0);
  return reactor;
}

}  // namespace tod::server
