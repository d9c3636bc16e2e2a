// The Open Inference Protocol (KServe v2) gRPC service, inference.GRPCInferenceService, on the
// gRPC port beside tod.v1.ObstacleDiscovery, on the same engine, limits, metrics and access log:
//
//   ServerLive      always live while it answers       (open, like grpc.health.v1)
//   ServerReady     a model is loaded and not draining (open)
//   ModelReady      the named model and version, ready or NOT_FOUND
//   ServerMetadata  name "tod", version, extensions
//   ModelMetadata   the model's input and outputs (oip_model.h)
//   ModelInfer      one frame: the BYTES input "image", options as request parameters named like
//                   the REST query; outputs in raw_output_contents (oip_grpc_messages.h)
//
// With auth, every method but ServerLive and ServerReady needs "authorization: Bearer <token>",
// as /v2 and /v2/models/... do on REST. ModelInfer is registered raw (ByteBuffer) so that a
// request that does not parse gets INVALID_ARGUMENT with a message; the client's deadline and
// cancellation stop its work as on tod.v1.
#pragma once

#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>
#include <string>

#include "inference/grpc_service.grpc.pb.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/metrics.h"
#include "server/oip/oip_tensors.h"
#include "server/token_auth.h"

namespace tod::server::oip {

// The five metadata methods typed, ModelInfer raw (the typed ModelInfer is never in the chain).
using Inference = inference::GRPCInferenceService;
using OipGrpcServiceBase = Inference::WithCallbackMethod_ServerLive<
    Inference::WithCallbackMethod_ServerReady<Inference::WithCallbackMethod_ModelReady<
        Inference::WithCallbackMethod_ServerMetadata<Inference::WithCallbackMethod_ModelMetadata<
            Inference::WithRawCallbackMethod_ModelInfer<Inference::Service>>>>>>;

class OipGrpcService final : public OipGrpcServiceBase {
 public:
  // The references must outlive the service; `next_request_id` numbers requests with tod.v1's.
  OipGrpcService(InferenceEngine& engine, const ModelHolder& models, ServerMetrics& metrics,
                 size_t max_image_bytes, std::function<std::string()> next_request_id,
                 std::shared_ptr<const TokenAuthenticator> auth = nullptr);

  grpc::ServerUnaryReactor* ServerLive(grpc::CallbackServerContext* context,
                                       const inference::ServerLiveRequest* request,
                                       inference::ServerLiveResponse* response) override;
  grpc::ServerUnaryReactor* ServerReady(grpc::CallbackServerContext* context,
                                        const inference::ServerReadyRequest* request,
                                        inference::ServerReadyResponse* response) override;
  grpc::ServerUnaryReactor* ModelReady(grpc::CallbackServerContext* context,
                                       const inference::ModelReadyRequest* request,
                                       inference::ModelReadyResponse* response) override;
  grpc::ServerUnaryReactor* ServerMetadata(grpc::CallbackServerContext* context,
                                           const inference::ServerMetadataRequest* request,
                                           inference::ServerMetadataResponse* response) override;
  grpc::ServerUnaryReactor* ModelMetadata(grpc::CallbackServerContext* context,
                                          const inference::ModelMetadataRequest* request,
                                          inference::ModelMetadataResponse* response) override;
  grpc::ServerUnaryReactor* ModelInfer(grpc::CallbackServerContext* context,
                                       const grpc::ByteBuffer* request,
                                       grpc::ByteBuffer* response) override;

 private:
  // A finished unary call with `status` (the token refusal, when there is one, comes first).
  grpc::ServerUnaryReactor* Answer(grpc::CallbackServerContext* context, grpc::Status status);

  InferenceEngine& engine_;
  const ModelHolder& models_;
  ServerMetrics& metrics_;
  const BodyLimits limits_;
  const std::function<std::string()> next_request_id_;
  const std::shared_ptr<const TokenAuthenticator> auth_;
};

}  // namespace tod::server::oip
