// gRPC frontend: thin callback-API service classes that translate tod.v1 messages to engine
// requests and engine results back to messages and status codes.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cstdint>
#include <string>

#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/metrics.h"
#include "tod/v1/obstacle_discovery.grpc.pb.h"

namespace tod::server {

class ObstacleDiscoveryService final : public tod::v1::ObstacleDiscovery::CallbackService {
 public:
  // All three must outlive the service.
  ObstacleDiscoveryService(InferenceEngine& engine, const ModelHolder& models,
                           ServerMetrics& metrics);

  grpc::ServerUnaryReactor* Detect(grpc::CallbackServerContext* context,
                                   const tod::v1::DetectRequest* request,
                                   tod::v1::DetectResponse* response) override;
  grpc::ServerBidiReactor<tod::v1::DetectRequest, tod::v1::DetectResponse>* DetectStream(
      grpc::CallbackServerContext* context) override;
  grpc::ServerUnaryReactor* GetModelInfo(grpc::CallbackServerContext* context,
                                         const tod::v1::GetModelInfoRequest* request,
                                         tod::v1::ModelInfo* response) override;

  // Used by the stream reactor: submits one frame; `done` gets the status and filled response.
  void SubmitFrame(grpc::CallbackServerContext* context, const tod::v1::DetectRequest& request,
                   const std::string& default_frame_id, tod::v1::DetectResponse* response,
                   std::function<void(grpc::Status)> done);
  std::string NextRequestId();

 private:
  InferenceEngine& engine_;
  const ModelHolder& models_;
  ServerMetrics& metrics_;
  std::atomic<uint64_t> request_counter_{0};
};

}  // namespace tod::server
