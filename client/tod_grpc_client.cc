#include "client/tod_grpc_client.h"

#include <climits>
#include <thread>

namespace tod::client {

TodGrpcClient::TodGrpcClient(const std::string& address) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(INT_MAX);  // responses carry probability-map PNGs
  args.SetMaxSendMessageSize(INT_MAX);     // the server decides what is too large
  channel_ = grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
  stub_ = tod::v1::ObstacleDiscovery::NewStub(channel_);
  health_ = grpc::health::v1::Health::NewStub(channel_);
}

grpc::Status TodGrpcClient::Detect(const tod::v1::DetectRequest& request,
                                   tod::v1::DetectResponse* response,
                                   std::optional<std::chrono::milliseconds> timeout) {
  grpc::ClientContext context;
  if (timeout) context.set_deadline(std::chrono::system_clock::now() + *timeout);
  return stub_->Detect(&context, request, response);
}

grpc::Status TodGrpcClient::DetectStream(
    const std::vector<tod::v1::DetectRequest>& requests,
    const std::function<void(const tod::v1::DetectResponse&)>& on_response) {
  grpc::ClientContext context;
  auto stream = stub_->DetectStream(&context);
  // Writing and reading concurrently: the server answers frame by frame, so a writer that waited
  // for all its writes before reading could stall on flow control with large maps.
  std::thread writer([&] {
    for (const tod::v1::DetectRequest& request : requests) {
      if (!stream->Write(request)) break;  // the server ended the stream
    }
    stream->WritesDone();
  });
  tod::v1::DetectResponse response;
  while (stream->Read(&response)) on_response(response);
  writer.join();
  return stream->Finish();
}

grpc::Status TodGrpcClient::GetModelInfo(tod::v1::ModelInfo* info,
                                         std::chrono::milliseconds timeout) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + timeout);
  return stub_->GetModelInfo(&context, tod::v1::GetModelInfoRequest(), info);
}

grpc::Status TodGrpcClient::Health(const std::string& service,
                                   grpc::health::v1::HealthCheckResponse* response,
                                   std::chrono::milliseconds timeout) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + timeout);
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  return health_->Check(&context, request, response);
}

}  // namespace tod::client
