#include "client/tod_grpc_client.h"

#include <climits>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

namespace tod::client {

namespace {

tod::Result<std::string> ReadText(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return tod::Status::NotFound(what + " " + path + ": cannot open");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string ReadOrEmpty(const std::string& path) {
  tod::Result<std::string> text = ReadText(path, "");
  return text.ok() ? *text : std::string();
}

}  // namespace

tod::Result<ConnectionOptions> LoadConnectionOptions(const std::string& tls_ca_file,
                                                     const std::string& tls_cert_file,
                                                     const std::string& tls_key_file,
                                                     const std::string& token_file) {
  ConnectionOptions options;
  options.tls_ca_file = tls_ca_file;
  options.tls_cert_file = tls_cert_file;
  options.tls_key_file = tls_key_file;
  if (tls_cert_file.empty() != tls_key_file.empty()) {
    return tod::Status::InvalidArgument("--tls-cert and --tls-key go together");
  }
  if (!tls_cert_file.empty() && tls_ca_file.empty()) {
    return tod::Status::InvalidArgument("--tls-cert needs --tls-ca (the server's CA)");
  }
  for (const auto& [flag, path] :
       {std::pair<const char*, const std::string&>{"--tls-ca", tls_ca_file},
        {"--tls-cert", tls_cert_file},
        {"--tls-key", tls_key_file}}) {
    if (path.empty()) continue;
    if (auto text = ReadText(path, flag); !text.ok()) return text.status();
  }
  if (!token_file.empty()) {
    auto text = ReadText(token_file, "--token-file");
    if (!text.ok()) return text.status();
    std::istringstream lines(*text);
    std::string line;
    while (options.token.empty() && std::getline(lines, line)) {
      const size_t begin = line.find_first_not_of(" \t\r");
      if (begin == std::string::npos || line[begin] == '#') continue;
      options.token = line.substr(begin, line.find_last_not_of(" \t\r") - begin + 1);
    }
    if (options.token.empty()) {
      return tod::Status::InvalidArgument("--token-file " + token_file + ": no token in it");
    }
  }
  return options;
}

TodGrpcClient::TodGrpcClient(const std::string& address, ConnectionOptions options)
    : token_(std::move(options.token)) {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(INT_MAX);  // responses carry probability-map PNGs
  args.SetMaxSendMessageSize(INT_MAX);     // the server decides what is too large
  std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
  if (!options.tls_ca_file.empty()) {
    // Unreadable files leave the field empty; the handshake then fails with gRPC's own message.
    grpc::SslCredentialsOptions ssl;
    ssl.pem_root_certs = ReadOrEmpty(options.tls_ca_file);
    if (!options.tls_cert_file.empty()) {
      ssl.pem_cert_chain = ReadOrEmpty(options.tls_cert_file);
      ssl.pem_private_key = ReadOrEmpty(options.tls_key_file);
    }
    credentials = grpc::SslCredentials(ssl);
  }
  channel_ = grpc::CreateCustomChannel(address, credentials, args);
  stub_ = tod::v1::ObstacleDiscovery::NewStub(channel_);
  health_ = grpc::health::v1::Health::NewStub(channel_);
}

grpc::Status TodGrpcClient::Detect(const tod::v1::DetectRequest& request,
                                   tod::v1::DetectResponse* response,
                                   std::optional<std::chrono::milliseconds> timeout) {
  grpc::ClientContext context;
  Prepare(&context, timeout);
  return stub_->Detect(&context, request, response);
}

grpc::Status TodGrpcClient::DetectStream(
    const std::vector<tod::v1::DetectRequest>& requests,
    const std::function<void(const tod::v1::DetectResponse&)>& on_response) {
  grpc::ClientContext context;
  Prepare(&context, std::nullopt);
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
                                         std::chrono::milliseconds timeout,
                                         const std::string& model) {
  grpc::ClientContext context;
  Prepare(&context, timeout);
  tod::v1::GetModelInfoRequest request;
  request.set_model(model);
  return stub_->GetModelInfo(&context, request, info);
}

grpc::Status TodGrpcClient::Health(const std::string& service,
                                   grpc::health::v1::HealthCheckResponse* response,
                                   std::chrono::milliseconds timeout) {
  grpc::ClientContext context;
  Prepare(&context, timeout);
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(service);
  return health_->Check(&context, request, response);
}

void TodGrpcClient::Prepare(grpc::ClientContext* context,
                            std::optional<std::chrono::milliseconds> timeout) const {
  if (timeout) context->set_deadline(std::chrono::system_clock::now() + *timeout);
  if (!token_.empty()) context->AddMetadata("authorization", "Bearer " + token_);
}

}  // namespace tod::client
