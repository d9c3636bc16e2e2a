// A small synchronous client for tod.v1.ObstacleDiscovery and grpc.health.v1, shared by tod_client
// and tod_load.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "tod/v1/obstacle_discovery.grpc.pb.h"

namespace tod::client {

// How to reach a server that runs TLS and/or bearer tokens. Empty fields: plaintext, no token.
struct ConnectionOptions {
  std::string tls_ca_file;    // PEM CA that signed the server's certificate: connect over TLS
  std::string tls_cert_file;  // PEM client certificate and key, for servers that require mTLS
  std::string tls_key_file;
  std::string token;  // sent as "authorization: Bearer <token>"
};

// Reads the flags' files (--tls-ca, --tls-cert, --tls-key, --token-file: the first non-empty,
// non-comment line of the token file) into ConnectionOptions; errors name the file.
tod::Result<ConnectionOptions> LoadConnectionOptions(const std::string& tls_ca_file,
                                                     const std::string& tls_cert_file,
                                                     const std::string& tls_key_file,
                                                     const std::string& token_file);

class TodGrpcClient {
 public:
  // address: "host:port"; a channel sized for large frames and maps, TLS when options say so.
  explicit TodGrpcClient(const std::string& address, ConnectionOptions options = {});

  grpc::Status Detect(const tod::v1::DetectRequest& request, tod::v1::DetectResponse* response,
                      std::optional<std::chrono::milliseconds> timeout = std::nullopt);
  // Sends every request on one stream (from a writer thread) and calls on_response for each
  // response as it arrives. Returns the stream's final status.
  grpc::Status DetectStream(const std::vector<tod::v1::DetectRequest>& requests,
                            const std::function<void(const tod::v1::DetectResponse&)>& on_response);
  // The info of the model named `model` (the server's default when empty).
  grpc::Status GetModelInfo(tod::v1::ModelInfo* info,
                            std::chrono::milliseconds timeout = std::chrono::seconds(10),
                            const std::string& model = "");
  // Standard health check; service "" is the whole server.
  grpc::Status Health(const std::string& service, grpc::health::v1::HealthCheckResponse* response,
                      std::chrono::milliseconds timeout = std::chrono::seconds(5));

 private:
  // A context carrying the token (if any) and, when given, a deadline `timeout` from now.
  void Prepare(grpc::ClientContext* context,
               std::optional<std::chrono::milliseconds> timeout) const;

  std::string token_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<tod::v1::ObstacleDiscovery::Stub> stub_;
  std::unique_ptr<grpc::health::v1::Health::Stub> health_;
};

}  // namespace tod::client
