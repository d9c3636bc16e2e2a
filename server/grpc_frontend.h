// gRPC frontend: thin callback-API service classes that translate tod.v1 messages to engine
// requests and engine results back to messages and status codes. The methods are registered raw
// (ByteBuffer in and out) and parse their requests themselves, so that a malformed request gets
// INVALID_ARGUMENT with a message (see grpc_messages.h).
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "server/access_log.h"
#include "server/core/cancellation.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/metrics.h"
#include "server/token_auth.h"
#include "tod/v1/obstacle_discovery.grpc.pb.h"

namespace tod::server {

using RawObstacleDiscoveryService = tod::v1::ObstacleDiscovery::WithRawCallbackMethod_Detect<
    tod::v1::ObstacleDiscovery::WithRawCallbackMethod_DetectStream<
        tod::v1::ObstacleDiscovery::WithRawCallbackMethod_GetModelInfo<
            tod::v1::ObstacleDiscovery::Service>>>;

class ObstacleDiscoveryService final : public RawObstacleDiscoveryService {
 public:
  // All three must outlive the service. With `auth`, every method needs the call metadata
  // "authorization: Bearer <token>" (UNAUTHENTICATED otherwise); grpc.health.v1 and reflection
  // are other services and stay open.
  ObstacleDiscoveryService(InferenceEngine& engine, const ModelHolder& models,
                           ServerMetrics& metrics,
                           std::shared_ptr<const TokenAuthenticator> auth = nullptr);

  grpc::ServerUnaryReactor* Detect(grpc::CallbackServerContext* context,
                                   const grpc::ByteBuffer* request,
                                   grpc::ByteBuffer* response) override;
  grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* DetectStream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* GetModelInfo(grpc::CallbackServerContext* context,
                                         const grpc::ByteBuffer* request,
                                         grpc::ByteBuffer* response) override;

  // Parses and submits one frame; `done` gets the status and, when OK, the serialised
  // DetectResponse in `response`. `done` may run inline or on a worker thread. The call's
  // reactor cancels `cancellation` when gRPC cancels the call. `stream_camera`: the horizon
  // track of the stream the frame came on (null for a unary call).
  void SubmitFrame(grpc::CallbackServerContext* context, const grpc::ByteBuffer& request,
                   const std::string& default_frame_id, std::shared_ptr<Cancellation> cancellation,
                   std::shared_ptr<CameraTrack> stream_camera, grpc::ByteBuffer* response,
                   std::function<void(grpc::Status)> done);
  std::string NextRequestId();

 private:
  // UNAUTHENTICATED (logged and counted) when auth is on and the call has no valid token.
  std::optional<grpc::Status> Refuse(const grpc::CallbackServerContext& context,
                                     const char* method);
  // CANCELLED when the call was cancelled before its request arrived whole, else the parse
  // error (INVALID_ARGUMENT, counted as bad_request); logged either way.
  grpc::Status RefuseUnparsed(const grpc::CallbackServerContext& context, const Status& parsed,
                              const AccessRecord& access);
  // Writes the access-log line of a frame that ended with `status` after `ms`.
  void LogFrame(AccessRecord access, const grpc::Status& status, double ms,
                const char* cancelled = nullptr);

  InferenceEngine& engine_;
  const ModelHolder& models_;
  ServerMetrics& metrics_;
  const std::shared_ptr<const TokenAuthenticator> auth_;
  std::atomic<uint64_t> request_counter_{0};
};

}  // namespace tod::server
