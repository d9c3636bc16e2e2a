// TLS for both listeners from PEM files: the server's certificate chain and key, and optionally a
// client CA, which turns on mutual TLS (clients must present a certificate that CA signed). The
// files are read and checked once at start-up; errors name the file and the problem.
#pragma once

#include <grpcpp/security/server_credentials.h>

#include <boost/asio/ssl/context.hpp>
#include <memory>
#include <string>

#include "core/base/status.h"

namespace tod::server {

struct TlsFiles {
  std::string cert;       // PEM certificate chain, leaf first
  std::string key;        // PEM private key of the leaf
  std::string client_ca;  // PEM CA certificates; empty: clients are not asked for certificates
  bool enabled() const { return !cert.empty() || !key.empty() || !client_ca.empty(); }
};

struct TlsMaterial {
  std::string cert_pem;
  std::string key_pem;
  std::string client_ca_pem;  // empty: server-side TLS only
  bool mutual() const { return !client_ca_pem.empty(); }
};

// Reads the files; refuses a half configuration (cert without key, a CA without cert and key)
// and a key that does not match the certificate.
Result<TlsMaterial> LoadTlsMaterial(const TlsFiles& files);

// gRPC: SSL server credentials, requiring and verifying a client certificate when mutual.
std::shared_ptr<grpc::ServerCredentials> GrpcServerCredentials(const TlsMaterial& tls);

// HTTPS: a TLS 1.2+ server context, verifying client certificates when mutual.
Result<std::shared_ptr<boost::asio::ssl::context>> HttpsContext(const TlsMaterial& tls);

}  // namespace tod::server
