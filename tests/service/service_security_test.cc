// End-to-end TLS, mutual TLS and bearer tokens through the real tod_server on loopback, with
// certificates made at test time (tests/service/test_pki.h).
#include <gtest/gtest.h>
#include <httplib.h>
#include <signal.h>

#include <filesystem>
#include <fstream>

#include "client/tod_grpc_client.h"
#include "tests/service/raw_http.h"
#include "tests/service/server_harness.h"
#include "tests/service/test_images.h"
#include "tests/service/test_pki.h"

namespace tod::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::HarnessTls;
using testing::MetricValue;
using testing::RunCommand;
using testing::ServerProcess;
using testing::TestModel;
using testing::TestPki;

constexpr char kToken[] = "first-token-0123456789abcdef";
constexpr char kOtherToken[] = "second-token-0123456789abcdef";

tod::v1::DetectRequest SmallRequest() {
  tod::v1::DetectRequest request;
  request.set_image(testing::RoadPng());
  request.mutable_options()->set_map_format(tod::v1::MAP_FORMAT_NONE);
  return request;
}

std::string WriteFile(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::trunc) << text;
  return path;
}

client::ConnectionOptions Connection(const TestPki& pki, const std::string& token = "",
                                     bool client_cert = false) {
  client::ConnectionOptions options;
  options.tls_ca_file = pki.ca_cert;
  if (client_cert) {
    options.tls_cert_file = pki.client_cert;
    options.tls_key_file = pki.client_key;
  }
  options.token = token;
  return options;
}

httplib::Result PostFrame(httplib::Client& client, const std::string& token) {
  httplib::Headers headers;
  if (!token.empty()) headers.emplace("Authorization", "Bearer " + token);
  return client.Post("/v1/detect?map=none", headers, testing::RoadPng(), "image/png");
}

class ServiceSecurityTest : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_MODEL();
    std::string log;
    std::optional<TestPki> pki = testing::MakeTestPki(&log);
    ASSERT_TRUE(pki.has_value()) << "openssl failed:\n" << log;
    pki_ = std::move(*pki);
    tokens_ = WriteFile(pki_.dir, "tokens", std::string("# fleet backends\n") + kToken + "\n");
  }
  TestPki pki_;
  std::string tokens_;
};

TEST_F(ServiceSecurityTest, TlsAndTokensOnGrpcAndHttpsWithProbesOpen) {
  auto server = ServerProcess::Start(TestModel(),
                                     {"--workers", "1", "--tls-cert", pki_.server_cert, "--tls-key",
                                      pki_.server_key, "--auth-token-file", tokens_},
                                     HarnessTls{pki_.ca_cert, "", ""});
  ASSERT_TRUE(server->WaitReady()) << server->Log();

  // gRPC over TLS: the token opens Detect and GetModelInfo; none or a wrong one is refused.
  client::TodGrpcClient with_token(server->grpc_address(), Connection(pki_, kToken));
  tod::v1::DetectResponse response;
  grpc::Status status = with_token.Detect(SmallRequest(), &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  tod::v1::ModelInfo info;
  ASSERT_TRUE(with_token.GetModelInfo(&info).ok());
  EXPECT_EQ(info.model_dir(), info.name());
  EXPECT_EQ(info.model_dir().find('/'), std::string::npos) << info.model_dir();
  // DetectStream over TLS with the token: one answer per frame, in order.
  std::vector<tod::v1::DetectRequest> frames(3, SmallRequest());
  for (size_t i = 0; i < frames.size(); ++i) frames[i].set_frame_id("tls-" + std::to_string(i));
  std::vector<std::string> streamed;
  status = with_token.DetectStream(
      frames, [&](const tod::v1::DetectResponse& r) { streamed.push_back(r.frame_id()); });
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(streamed, (std::vector<std::string>{"tls-0", "tls-1", "tls-2"}));
  for (const std::string& token : {std::string(), std::string(kOtherToken)}) {
    client::TodGrpcClient refused(server->grpc_address(), Connection(pki_, token));
    status = refused.Detect(SmallRequest(), &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << status.error_message();
    EXPECT_EQ(refused.GetModelInfo(&info).error_code(), grpc::StatusCode::UNAUTHENTICATED);
    int answered = 0;
    status =
        refused.DetectStream({SmallRequest()}, [&](const tod::v1::DetectResponse&) { ++answered; });
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << status.error_message();
    EXPECT_EQ(answered, 0);
    // Health stays open for probes.
    grpc::health::v1::HealthCheckResponse health;
    ASSERT_TRUE(refused.Health("", &health).ok());
    EXPECT_EQ(health.status(), grpc::health::v1::HealthCheckResponse::SERVING);
  }
  // A plaintext client cannot talk to the TLS port.
  client::TodGrpcClient plaintext(server->grpc_address());
  EXPECT_EQ(plaintext.Detect(SmallRequest(), &response, 10s).error_code(),
            grpc::StatusCode::UNAVAILABLE);

  // HTTPS: the same rules; probes and metrics need no token.
  const std::unique_ptr<httplib::Client> https = server->HttpClient();
  https->set_read_timeout(60s);
  auto answer = PostFrame(*https, kToken);
  ASSERT_TRUE(answer) << httplib::to_string(answer.error());
  EXPECT_EQ(answer->status, 200) << answer->body;
  for (const std::string& token : {std::string(), std::string(kOtherToken)}) {
    answer = PostFrame(*https, token);
    ASSERT_TRUE(answer);
    EXPECT_EQ(answer->status, 401) << answer->body;
    EXPECT_EQ(answer->get_header_value("WWW-Authenticate"), "Bearer");
    EXPECT_NE(answer->body.find("UNAUTHENTICATED"), std::string::npos) << answer->body;
  }
  EXPECT_EQ(https->Get("/v1/model")->status, 401);
  const auto model = https->Get("/v1/model", {{"Authorization", std::string("Bearer ") + kToken}});
  ASSERT_TRUE(model);
  EXPECT_EQ(model->status, 200);
  EXPECT_EQ(model->body.find(TestModel()), std::string::npos) << "server path leaked";
  EXPECT_EQ(https->Get("/v2/health/ready")->status, 200);
  EXPECT_EQ(https->Get("/v2/health/live")->status, 200);
  const std::string metrics = server->Metrics();
  ASSERT_FALSE(metrics.empty());
  EXPECT_EQ(MetricValue(metrics, R"(tod_http_refused_total{reason="unauthenticated"})"), 3);
  EXPECT_GE(MetricValue(metrics, R"(tod_rejections_total{reason="unauthenticated"})").value_or(0),
            6);

  // Plain HTTP on the HTTPS port: no answer, the failed handshake is counted.
  testing::RawConnection plain(server->http_port());
  ASSERT_TRUE(plain.connected());
  plain.Send("GET /v2/health/live HTTP/1.1\r\nHost: x\r\n\r\n");
  EXPECT_FALSE(plain.ReadResponse(10s).has_value());
  EXPECT_TRUE(server->WaitForMetric(R"(tod_http_refused_total{reason="tls_handshake"})", 1));

  // The command-line client with --tls-ca and --token-file.
  const std::string token_file = WriteFile(pki_.dir, "client_token", std::string(kToken) + "\n");
  const auto cli =
      RunCommand({testing::BinaryPath("tod_client"), "info", "--addr", server->grpc_address(),
                  "--tls-ca", pki_.ca_cert, "--token-file", token_file});
  EXPECT_EQ(cli.exit_code, 0) << cli.output;
  const auto cli_without = RunCommand({testing::BinaryPath("tod_client"), "info", "--addr",
                                       server->grpc_address(), "--tls-ca", pki_.ca_cert});
  EXPECT_EQ(cli_without.exit_code, 1) << cli_without.output;
  const auto health = RunCommand({testing::BinaryPath("tod_client"), "health", "--addr",
                                  server->grpc_address(), "--tls-ca", pki_.ca_cert});
  EXPECT_EQ(health.exit_code, 0) << health.output;
  // tod_load over HTTPS and over gRPC with TLS, with the token.
  const std::string images = testing::MakeTempDir("tod_tls_images");
  WriteFile(images, "frame.png", testing::RoadPng());
  for (const bool http : {false, true}) {
    std::vector<std::string> argv = {
        testing::BinaryPath("tod_load"),
        "--addr",
        http ? "127.0.0.1:" + std::to_string(server->http_port()) : server->grpc_address(),
        "--images",
        images,
        "--concurrency",
        "1",
        "--duration",
        "1",
        "--warmup",
        "0",
        "--tls-ca",
        pki_.ca_cert,
        "--token-file",
        token_file};
    if (http) argv.push_back("--http");
    const auto load = RunCommand(argv);
    EXPECT_EQ(load.exit_code, 0) << load.output;
    EXPECT_EQ(load.output.find("401"), std::string::npos) << load.output;
    EXPECT_EQ(load.output.find("UNAUTHENTICATED"), std::string::npos) << load.output;
  }
}

TEST_F(ServiceSecurityTest, MutualTlsNeedsAClientCertificateFromTheClientCa) {
  auto server = ServerProcess::Start(TestModel(),
                                     {"--workers", "1", "--tls-cert", pki_.server_cert, "--tls-key",
                                      pki_.server_key, "--tls-client-ca", pki_.ca_cert},
                                     HarnessTls{pki_.ca_cert, pki_.client_cert, pki_.client_key});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  tod::v1::DetectResponse response;
  client::TodGrpcClient with_cert(server->grpc_address(), Connection(pki_, "", true));
  const grpc::Status ok = with_cert.Detect(SmallRequest(), &response);
  EXPECT_TRUE(ok.ok()) << ok.error_message();
  client::TodGrpcClient without_cert(server->grpc_address(), Connection(pki_));
  EXPECT_EQ(without_cert.Detect(SmallRequest(), &response, 10s).error_code(),
            grpc::StatusCode::UNAVAILABLE);
  client::ConnectionOptions stranger = Connection(pki_);
  stranger.tls_cert_file = pki_.stranger_cert;
  stranger.tls_key_file = pki_.stranger_key;
  client::TodGrpcClient wrong_ca(server->grpc_address(), stranger);
  EXPECT_EQ(wrong_ca.Detect(SmallRequest(), &response, 10s).error_code(),
            grpc::StatusCode::UNAVAILABLE);

  const std::unique_ptr<httplib::Client> https = server->HttpClient();  // with the client cert
  https->set_read_timeout(60s);
  const auto answer = PostFrame(*https, "");
  ASSERT_TRUE(answer) << httplib::to_string(answer.error());
  EXPECT_EQ(answer->status, 200);
  const std::string address = "https://127.0.0.1:" + std::to_string(server->http_port());
  httplib::Client no_cert(address);
  no_cert.set_ca_cert_path(pki_.ca_cert.c_str());
  no_cert.enable_server_certificate_verification(true);
  EXPECT_FALSE(no_cert.Get("/v2/health/live")) << "a client without a certificate got an answer";
  httplib::Client foreign(address, pki_.stranger_cert, pki_.stranger_key);
  foreign.set_ca_cert_path(pki_.ca_cert.c_str());
  foreign.enable_server_certificate_verification(true);
  EXPECT_FALSE(foreign.Get("/v2/health/live")) << "a certificate from another CA got an answer";
  EXPECT_TRUE(server->WaitForMetric(R"(tod_http_refused_total{reason="tls_handshake"})", 2));
}

// Tokens from the environment (TOD_AUTH_TOKEN_FILE); SIGHUP swaps them; a broken file keeps the
// previous ones. Plain HTTP and gRPC here: tokens do not need TLS.
TEST_F(ServiceSecurityTest, TokensReloadOnSighup) {
  setenv("TOD_AUTH_TOKEN_FILE", tokens_.c_str(), 1);
  auto server = ServerProcess::Start(TestModel(), {"--workers", "1"});
  unsetenv("TOD_AUTH_TOKEN_FILE");
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const std::unique_ptr<httplib::Client> http = server->HttpClient();
  http->set_read_timeout(60s);
  EXPECT_EQ(PostFrame(*http, kToken)->status, 200);
  EXPECT_EQ(PostFrame(*http, kOtherToken)->status, 401);

  WriteFile(pki_.dir, "tokens", std::string(kOtherToken) + "\n");
  server->Signal(SIGHUP);
  ASSERT_TRUE(server->WaitForMetric(R"(tod_auth_token_reloads_total{result="success"})", 1))
      << server->Log();
  EXPECT_EQ(PostFrame(*http, kOtherToken)->status, 200);
  EXPECT_EQ(PostFrame(*http, kToken)->status, 401);
  tod::v1::DetectResponse response;
  client::ConnectionOptions other;
  other.token = kOtherToken;
  EXPECT_TRUE(
      client::TodGrpcClient(server->grpc_address(), other).Detect(SmallRequest(), &response).ok());

  WriteFile(pki_.dir, "tokens", "# nothing left\n");
  server->Signal(SIGHUP);
  ASSERT_TRUE(server->WaitForMetric(R"(tod_auth_token_reloads_total{result="failure"})", 1))
      << server->Log();
  EXPECT_EQ(PostFrame(*http, kOtherToken)->status, 200) << "a broken file keeps the old tokens";
  EXPECT_NE(server->Log().find("token reload refused"), std::string::npos);
  EXPECT_EQ(server->Log().find(kOtherToken), std::string::npos) << "a token was logged";
}

TEST_F(ServiceSecurityTest, UnusableTlsOrTokenFilesStopStartup) {
  const auto check = [](const std::vector<std::string>& args, const std::string& named) {
    std::vector<std::string> argv = {testing::BinaryPath("tod_server"),
                                     "--model",
                                     TestModel(),
                                     "--host",
                                     "127.0.0.1",
                                     "--grpc-port",
                                     "0",
                                     "--http-port",
                                     "0"};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto run = RunCommand(argv);
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find(named), std::string::npos) << run.output;
  };
  check({"--tls-cert", pki_.server_cert}, "tls_key");
  check({"--tls-cert", pki_.server_cert, "--tls-key", pki_.dir + "/missing.key"}, "missing.key");
  check({"--tls-cert", pki_.server_cert, "--tls-key", pki_.client_key}, "private key");
  check({"--auth-token-file", WriteFile(pki_.dir, "short", "abc\n")}, "line 1");
  check({"--auth-token-file", pki_.dir + "/none"}, "none");
}

}  // namespace
}  // namespace tod::server
