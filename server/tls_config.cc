#include "server/tls_config.h"

#include <grpcpp/security/server_credentials.h>
#include <openssl/ssl.h>

#include <fstream>
#include <iterator>

namespace tod::server {
namespace {

namespace ssl = boost::asio::ssl;

Result<std::string> ReadPem(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound(what + " " + path + ": cannot open");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.find("-----BEGIN ") == std::string::npos) {
    return Status::InvalidArgument(what + " " + path + ": not a PEM file");
  }
  return text;
}

}  // namespace

Result<TlsMaterial> LoadTlsMaterial(const TlsFiles& files) {
  if (files.cert.empty() != files.key.empty()) {
    return Status::InvalidArgument("tls: --tls-cert and --tls-key go together");
  }
  if (files.cert.empty() && !files.client_ca.empty()) {
    return Status::InvalidArgument("tls: --tls-client-ca needs --tls-cert and --tls-key");
  }
  TlsMaterial tls;
  auto cert = ReadPem(files.cert, "tls_cert");
  if (!cert.ok()) return cert.status();
  auto key = ReadPem(files.key, "tls_key");
  if (!key.ok()) return key.status();
  tls.cert_pem = std::move(*cert);
  tls.key_pem = std::move(*key);
  if (!files.client_ca.empty()) {
    auto ca = ReadPem(files.client_ca, "tls_client_ca");
    if (!ca.ok()) return ca.status();
    tls.client_ca_pem = std::move(*ca);
  }
  // Building the HTTPS context parses everything and checks that the key fits the certificate,
  // so a broken file stops start-up here rather than at the first handshake.
  if (auto context = HttpsContext(tls); !context.ok()) {
    return Status::InvalidArgument("tls (" + files.cert + ", " + files.key +
                                   (files.client_ca.empty() ? "" : ", " + files.client_ca) +
                                   "): " + context.status().message());
  }
  return tls;
}

std::shared_ptr<grpc::ServerCredentials> GrpcServerCredentials(const TlsMaterial& tls) {
  grpc::SslServerCredentialsOptions options(
      tls.mutual() ? GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY
                   : GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE);
  options.pem_root_certs = tls.client_ca_pem;
  options.pem_key_cert_pairs.push_back({tls.key_pem, tls.cert_pem});
  return grpc::SslServerCredentials(options);
}

Result<std::shared_ptr<ssl::context>> HttpsContext(const TlsMaterial& tls) {
  auto context = std::make_shared<ssl::context>(ssl::context::tls_server);
  boost::system::error_code ec;
  context->set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 |
                           ssl::context::no_sslv3 | ssl::context::no_tlsv1 |
                           ssl::context::no_tlsv1_1 | ssl::context::single_dh_use,
                       ec);
  if (!ec) {
    context->use_certificate_chain(boost::asio::buffer(tls.cert_pem), ec);
    if (ec) return Status::InvalidArgument("certificate: " + ec.message());
  }
  if (!ec) {
    context->use_private_key(boost::asio::buffer(tls.key_pem), ssl::context::pem, ec);
    if (ec) return Status::InvalidArgument("private key: " + ec.message());
  }
  if (!ec && SSL_CTX_check_private_key(context->native_handle()) != 1) {
    return Status::InvalidArgument("the private key does not match the certificate");
  }
  if (!ec && tls.mutual()) {
    context->add_certificate_authority(boost::asio::buffer(tls.client_ca_pem), ec);
    if (ec) return Status::InvalidArgument("client CA: " + ec.message());
    context->set_verify_mode(ssl::verify_peer | ssl::verify_fail_if_no_peer_cert, ec);
  }
  if (ec) return Status::InvalidArgument(ec.message());
  return context;
}

}  // namespace tod::server
