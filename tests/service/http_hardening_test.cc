// End-to-end hardening tests (issue 12): the real tod_server on loopback, probed the way an
// attacker or a broken client would: endless bodies and headers, trickling clients, requests
// without a length, small images claiming huge sizes, corrupt images, absurd option values,
// malformed protobuf bytes and wrong methods. Each test fails on the cpp-httplib front end and
// the OpenCV decoder this replaced.
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <thread>

#include "client/tod_grpc_client.h"
#include "tests/service/raw_http.h"
#include "tests/service/server_harness.h"
#include "tests/service/shared_server_test.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

using namespace std::chrono_literals;
using testing::MetricValue;
using testing::RawConnection;
using testing::ScrapeMetrics;
using testing::ServerProcess;
using testing::TestModel;

constexpr uint64_t kMiB = 1u << 20;

std::vector<std::string> ServerArgsWith(std::vector<std::string> args) {
  args.insert(args.end(), {"--workers", "2", "--log-format", "json"});
  return args;
}

std::unique_ptr<ServerProcess> StartServer(std::vector<std::string> args) {
  return ServerProcess::Start(TestModel(), ServerArgsWith(std::move(args)));
}

double Refused(int http_port, const std::string& reason) {
  return MetricValue(ScrapeMetrics(http_port), "tod_http_refused_total{reason=\"" + reason + "\"}")
      .value_or(0);
}

std::string ErrorMessage(const std::string& body) {
  const nlohmann::json json = nlohmann::json::parse(body, nullptr, false);
  return json.is_discarded() ? "" : json["error"].value("message", "");
}

// A textured frame, so that its JPEG has real entropy-coded data to damage.
cv::Mat3b NoisyFrame() {
  cv::Mat3b noise(160, 320);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 60);
  cv::Mat3b frame;
  cv::add(testing::RoadFrame(), noise, frame);
  return frame;
}

std::string Zeroed(std::string bytes, double from, double to) {
  const size_t begin = static_cast<size_t>(bytes.size() * from);
  const size_t end = static_cast<size_t>(bytes.size() * to);
  std::fill(bytes.begin() + static_cast<long>(begin), bytes.begin() + static_cast<long>(end), '\0');
  return bytes;
}

// A 1000-byte JPEG whose frame header claims width x height.
std::string JpegClaiming(int width, int height) {
  cv::Mat3b small(64, 64);
  cv::RNG rng(3);
  rng.fill(small, cv::RNG::UNIFORM, 0, 255);
  std::string jpeg = testing::Encode(small, ".jpg");
  const size_t sof = jpeg.find("\xFF\xC0");
  EXPECT_NE(sof, std::string::npos);
  jpeg[sof + 5] = static_cast<char>(height >> 8);
  jpeg[sof + 6] = static_cast<char>(height & 0xFF);
  jpeg[sof + 7] = static_cast<char>(width >> 8);
  jpeg[sof + 8] = static_cast<char>(width & 0xFF);
  jpeg.resize(1000, '\0');
  return jpeg;
}

class HttpHardeningTest : public testing::SharedServerTest<HttpHardeningTest> {
 public:
  // The default limits: they are what is being tested.
  static std::vector<std::string> ServerArgs() { return ServerArgsWith({}); }

 protected:
  void SetUp() override {
    SharedServerTest::SetUp();
    if (HasFatalFailure()) return;
    http_ = std::make_unique<httplib::Client>("127.0.0.1", server_->http_port());
    http_->set_read_timeout(60s);
  }
  int port() const { return server_->http_port(); }

  std::unique_ptr<httplib::Client> http_;
};

// Probe: a chunked body of 1 GiB used to be read whole before the 16 MiB cap applied.
TEST(HttpHardeningOwnServerTest, ChunkedBodyIsCountedWhileReading) {
  REQUIRE_MODEL();
  auto server = StartServer({});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const testing::MemoryKb before = testing::ProcessMemory(server->pid());
  RawConnection connection(server->http_port());
  ASSERT_TRUE(connection.connected());
  const auto streamed = connection.StreamUntilAnswered(
      "POST /v1/detect HTTP/1.1\r\nHost: t\r\nContent-Type: image/png\r\n"
      "Transfer-Encoding: chunked\r\n\r\n",
      testing::HttpChunk(std::string(kMiB, 'x')), uint64_t{1} << 30, 120s);
  ASSERT_TRUE(streamed.response) << "no answer after " << streamed.sent << " bytes";
  EXPECT_EQ(streamed.response->status, 413) << streamed.response->body;
  EXPECT_NE(ErrorMessage(streamed.response->body).find("16777216 bytes"), std::string::npos);
  // Cut at the 16 MiB limit (plus what the socket buffers held), far from 1 GiB.
  EXPECT_LT(streamed.sent, 64 * kMiB);
  const testing::MemoryKb after = testing::ProcessMemory(server->pid());
  EXPECT_LT(after.peak - before.rss, 200 * 1024) << "kB; before " << before.rss;
  EXPECT_EQ(Refused(server->http_port(), "body_too_large"), 1);
  EXPECT_NE(server->Log().find("body_too_large"), std::string::npos);
}

// Probe: one 300 MB header line without a newline used to be buffered whole, with no reply.
TEST(HttpHardeningOwnServerTest, EndlessHeaderLineIsCutAtTheLimit) {
  REQUIRE_MODEL();
  auto server = StartServer({});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const testing::MemoryKb before = testing::ProcessMemory(server->pid());
  RawConnection connection(server->http_port());
  ASSERT_TRUE(connection.connected());
  const auto streamed = connection.StreamUntilAnswered(
      "GET /v2/health/live?x=", std::string(kMiB, 'a'), 300 * kMiB, 120s);
  ASSERT_TRUE(streamed.response) << "no answer after " << streamed.sent << " bytes";
  EXPECT_EQ(streamed.response->status, 431) << streamed.response->body;
  EXPECT_LT(streamed.sent, 32 * kMiB);
  const testing::MemoryKb after = testing::ProcessMemory(server->pid());
  EXPECT_LT(after.peak - before.rss, 100 * 1024) << "kB; before " << before.rss;
  EXPECT_EQ(Refused(server->http_port(), "header_too_large"), 1);
}

// Probe: 16 connections trickling headers or bodies at 1 byte/s used to take every REST thread,
// so the liveness probe stopped answering for as long as they trickled.
TEST(HttpHardeningOwnServerTest, TricklingClientsNeitherBlockProbesNorStayForever) {
  REQUIRE_MODEL();
  // Default limits: the whole-request deadline is 30 s.
  auto server = StartServer({});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  constexpr int kTricklers = 16;
  std::vector<std::unique_ptr<RawConnection>> tricklers;
  for (int i = 0; i < kTricklers; ++i) {
    tricklers.push_back(std::make_unique<RawConnection>(server->http_port()));
    ASSERT_TRUE(tricklers.back()->connected());
    ASSERT_TRUE(tricklers.back()->Send(
        i % 2 == 0 ? "POST /v1/detect HTTP/1.1\r\nHost: t\r\nX-Slow: "
                   : "POST /v1/detect HTTP/1.1\r\nHost: t\r\nContent-Type: image/png\r\n"
                     "Content-Length: 100000\r\n\r\n"));
  }
  std::atomic<int> answered{0};
  std::atomic<bool> give_up{false};
  std::vector<int> statuses(kTricklers, 0);
  std::thread trickle([&] {
    // One byte a second on every connection still waiting, until each has its answer
    // (bounded: 120 rounds, far beyond the 30 s request deadline).
    for (int round = 0; round < 120 && answered < kTricklers && !give_up; ++round) {
      for (int i = 0; i < kTricklers; ++i) {
        RawConnection& connection = *tricklers[static_cast<size_t>(i)];
        int& status = statuses[static_cast<size_t>(i)];
        if (status != 0) continue;
        if (connection.Readable(0ms)) {
          const auto response = connection.ReadResponse(10s);
          status = response ? response->status : -1;
          ++answered;
        } else {
          connection.Send("a");
        }
      }
      std::this_thread::sleep_for(1s);
    }
  });
  // While all of them trickle, probes and real work are answered.
  httplib::Client probe("127.0.0.1", server->http_port());
  probe.set_connection_timeout(10s);
  probe.set_read_timeout(10s);
  int probes_answered = 0;
  int probes_while_trickling = 0;
  for (int i = 0; i < 5; ++i) {
    const auto live = probe.Get("/v2/health/live");
    if (!live) break;
    EXPECT_EQ(live->status, 200);
    ++probes_answered;
    if (answered == 0) ++probes_while_trickling;
  }
  int detect_status = -1;
  if (probes_answered == 5) {
    probe.set_read_timeout(60s);
    const auto detect = probe.Post("/v1/detect?map=none", testing::RoadPng(), "image/png");
    detect_status = detect ? detect->status : -1;
  }
  give_up = probes_answered < 5;
  trickle.join();
  EXPECT_EQ(probes_answered, 5) << "liveness probe not answered while clients trickle";
  EXPECT_EQ(detect_status, 200);
  EXPECT_GE(probes_while_trickling, 1) << "the trickling clients were cut before any probe";
  EXPECT_EQ(statuses, std::vector<int>(kTricklers, 408));
  EXPECT_EQ(Refused(server->http_port(), "read_timeout"), kTricklers);
}

// Probe: a POST without a body or Content-Length used to hold a thread for 30 s, unlogged.
TEST_F(HttpHardeningTest, PostWithoutLengthIsAnsweredAtOnceAndLogged) {
  const double before = Refused(port(), "length_required");
  RawConnection connection(port());
  ASSERT_TRUE(connection.connected());
  ASSERT_TRUE(
      connection.Send("POST /v1/detect HTTP/1.1\r\nHost: t\r\nContent-Type: image/png\r\n\r\n"));
  // The connection stays open on our side: the answer must not wait for it to close.
  const auto response = connection.ReadResponse(15s);
  ASSERT_TRUE(response) << "no answer within 15 s";
  EXPECT_EQ(response->status, 411) << response->body;
  EXPECT_NE(ErrorMessage(response->body).find("Content-Length"), std::string::npos);
  EXPECT_EQ(Refused(port(), "length_required"), before + 1);
  EXPECT_NE(server_->Log().find("length_required"), std::string::npos);
}

// Probe: a 1000-byte JPEG claiming 4000 x 4000 used to be decoded (20-116 s, +0.65 GB).
TEST_F(HttpHardeningTest, SmallJpegClaimingHugeSizeIsRefusedFromItsHeader) {
  const std::string bomb = JpegClaiming(4000, 4000);
  ASSERT_EQ(bomb.size(), 1000u);
  const auto start = std::chrono::steady_clock::now();
  const auto rest = http_->Post("/v1/detect", bomb, "image/jpeg");
  ASSERT_TRUE(rest);
  EXPECT_EQ(rest->status, 413) << rest->body;
  EXPECT_NE(ErrorMessage(rest->body).find("4000x4000"), std::string::npos) << rest->body;
  client::TodGrpcClient grpc(server_->grpc_address());
  tod::v1::DetectRequest request;
  request.set_image(bomb);
  tod::v1::DetectResponse response;
  const grpc::Status status = grpc.Detect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  // Refused before any decoding: nowhere near the seconds a 16 MP decode and pipeline take.
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s);
  // 2048 x 1024 camera frames fit the default 4 MP limit.
  const auto frame = http_->Post("/v1/detect?map=none", testing::RoadPng(2048, 1024), "image/png");
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->status, 200) << frame->body;
}

// Probe: truncated or partly zeroed JPEGs used to give 200 with detections made up from grey.
TEST_F(HttpHardeningTest, TruncatedOrZeroedImagesAreInvalid) {
  const std::string jpeg = testing::Encode(NoisyFrame(), ".jpg");
  const std::string png = testing::Encode(NoisyFrame(), ".png");
  const auto good = http_->Post("/v1/detect?map=none", jpeg, "image/jpeg");
  ASSERT_TRUE(good);
  ASSERT_EQ(good->status, 200) << good->body;
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"truncated JPEG", jpeg.substr(0, jpeg.size() / 2)},
      {"JPEG with a zeroed tail", Zeroed(jpeg, 0.6, 1.0)},
      {"JPEG with a zeroed middle", Zeroed(jpeg, 0.5, 0.6)},
      {"truncated PNG", png.substr(0, png.size() / 2)},
      {"PNG with a zeroed middle", Zeroed(png, 0.5, 0.55)},
      {"PNG without its end", png.substr(0, png.size() - 12)},
  };
  client::TodGrpcClient grpc(server_->grpc_address());
  for (const auto& [what, bytes] : damaged) {
    const std::string type = what.find("PNG") != std::string::npos ? "image/png" : "image/jpeg";
    const auto rest = http_->Post("/v1/detect?map=none", bytes, type.c_str());
    ASSERT_TRUE(rest) << what;
    EXPECT_EQ(rest->status, 400) << what << ": " << rest->body;
    EXPECT_NE(ErrorMessage(rest->body).find("decode"), std::string::npos) << rest->body;
    tod::v1::DetectRequest request;
    request.set_image(bytes);
    tod::v1::DetectResponse response;
    EXPECT_EQ(grpc.Detect(request, &response).error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << what;
  }
}

// Probe: two requests sent back to back on one connection: the first was answered, the second
// never (it waited in the buffer while the server waited for more bytes, until the idle timeout).
TEST_F(HttpHardeningTest, PipelinedRequestsAreAnsweredInOrder) {
  const std::string png = testing::Encode(NoisyFrame(), ".png");
  const std::string detect =
      "POST /v1/detect?map=none&frame_id=second HTTP/1.1\r\nHost: t\r\nContent-Type: image/png\r\n"
      "Content-Length: " +
      std::to_string(png.size()) + "\r\n\r\n" + png;
  RawConnection connection(port());
  ASSERT_TRUE(connection.connected());
  ASSERT_TRUE(connection.Send("GET /v2/health/live HTTP/1.1\r\nHost: t\r\n\r\n" + detect +
                              "GET /v1/model HTTP/1.1\r\nHost: t\r\n\r\n"));
  const auto live = connection.ReadResponse(60s);
  ASSERT_TRUE(live) << "the first of three pipelined requests was not answered";
  EXPECT_EQ(live->status, 200);
  EXPECT_NE(live->body.find("live"), std::string::npos) << live->body;
  const auto detected = connection.ReadResponse(60s);
  ASSERT_TRUE(detected) << "the second of three pipelined requests was not answered";
  ASSERT_EQ(detected->status, 200) << detected->body;
  EXPECT_EQ(nlohmann::json::parse(detected->body)["frame_id"], "second");
  const auto model = connection.ReadResponse(60s);
  ASSERT_TRUE(model) << "the third of three pipelined requests was not answered";
  EXPECT_EQ(model->status, 200) << model->body;
  EXPECT_TRUE(nlohmann::json::parse(model->body).contains("version")) << model->body;

  // A first request that asks to close: answered, then the connection ends (not left hanging).
  RawConnection closing(port());
  ASSERT_TRUE(closing.connected());
  ASSERT_TRUE(
      closing.Send("GET /v2/health/live HTTP/1.1\r\nHost: t\r\nConnection: close\r\n\r\n"
                   "GET /v2/health/live HTTP/1.1\r\nHost: t\r\n\r\n"));
  const auto first = closing.ReadResponse(60s);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->status, 200);
  EXPECT_TRUE(closing.WaitClosed(30s));
}

// WebP frames (what the obstacle benchmarks ship) are served like PNG and JPEG on REST and gRPC:
// a lossless WebP gives the detections of the PNG of the same pixels; a truncated one is 400 /
// INVALID_ARGUMENT.
TEST_F(HttpHardeningTest, WebpFramesAreServedAndBrokenOnesRefused) {
  const cv::Mat3b frame = NoisyFrame();
  std::vector<uchar> encoded;
  ASSERT_TRUE(cv::imencode(".webp", frame, encoded, {cv::IMWRITE_WEBP_QUALITY, 101}));
  const std::string webp(encoded.begin(), encoded.end());
  const auto from_png =
      http_->Post("/v1/detect?map=none", testing::Encode(frame, ".png"), "image/png");
  const auto from_webp = http_->Post("/v1/detect?map=none", webp, "image/webp");
  ASSERT_TRUE(from_png && from_webp);
  ASSERT_EQ(from_webp->status, 200) << from_webp->body;
  nlohmann::json png_json = nlohmann::json::parse(from_png->body);
  nlohmann::json webp_json = nlohmann::json::parse(from_webp->body);
  ASSERT_FALSE(webp_json["proposals"].empty()) << from_webp->body;
  EXPECT_EQ(webp_json["proposals"], png_json["proposals"]);
  EXPECT_EQ(webp_json["obstacles"], png_json["obstacles"]);

  client::TodGrpcClient grpc(server_->grpc_address());
  tod::v1::DetectRequest request;
  request.set_image(webp);
  tod::v1::DetectResponse response;
  const grpc::Status ok = grpc.Detect(request, &response);
  ASSERT_TRUE(ok.ok()) << ok.error_message();
  EXPECT_EQ(static_cast<size_t>(response.proposals_size()), webp_json["proposals"].size());

  const std::string truncated = webp.substr(0, webp.size() / 2);
  const auto rest = http_->Post("/v1/detect?map=none", truncated, "image/webp");
  ASSERT_TRUE(rest);
  EXPECT_EQ(rest->status, 400) << rest->body;
  EXPECT_NE(ErrorMessage(rest->body).find("WebP"), std::string::npos) << rest->body;
  request.set_image(truncated);
  EXPECT_EQ(grpc.Detect(request, &response).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

// Probe: timeout_ms=9223372036854775807 used to overflow into an immediate 504.
TEST_F(HttpHardeningTest, NumericOptionsAreRangeCheckedWithoutOverflow) {
  const std::string png = testing::RoadPng();
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"timeout_ms=9223372036854775807", "timeout_ms"},
      {"timeout_ms=99999999999999999999999", "timeout_ms"},
      {"timeout_ms=-1", "timeout_ms"},
      {"max_proposals=2147483648", "max_proposals"},
      {"max_proposals=-5", "max_proposals"},
      {"obstacle_threshold=nan", "obstacle_threshold"},
      {"obstacle_threshold=1e400", "obstacle_threshold"},
  };
  for (const auto& [query, option] : refused) {
    const auto result = http_->Post(("/v1/detect?" + query).c_str(), png, "image/png");
    ASSERT_TRUE(result) << query;
    EXPECT_EQ(result->status, 400) << query << ": " << result->body;
    EXPECT_NE(ErrorMessage(result->body).find(option), std::string::npos) << result->body;
  }
  const auto in_range =
      http_->Post("/v1/detect?map=none&timeout_ms=3600000&max_proposals=10000", png, "image/png");
  ASSERT_TRUE(in_range);
  EXPECT_EQ(in_range->status, 200) << in_range->body;
}

// Probe: malformed protobuf bytes used to get UNIMPLEMENTED with an empty message.
TEST_F(HttpHardeningTest, MalformedProtobufIsInvalidArgumentWithMessage) {
  const auto channel =
      grpc::CreateChannel(server_->grpc_address(), grpc::InsecureChannelCredentials());
  grpc::GenericStub stub(channel);
  auto call = [&](const std::string& method, const std::string& bytes) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + 30s);
    grpc::CompletionQueue queue;
    grpc::Slice slice(bytes);
    const grpc::ByteBuffer request(&slice, 1);
    auto rpc = stub.PrepareUnaryCall(&context, method, request, &queue);
    rpc->StartCall();
    grpc::ByteBuffer response;
    grpc::Status status;
    rpc->Finish(&response, &status, reinterpret_cast<void*>(1));
    void* tag = nullptr;
    bool ok = false;
    EXPECT_TRUE(queue.Next(&tag, &ok));
    queue.Shutdown();
    while (queue.Next(&tag, &ok)) {
    }
    return status;
  };
  // Field 1 (image) declaring 4 GB of bytes that are not there; then an invalid wire type.
  const std::string truncated_field("\x0a\xff\xff\xff\xff\x0f", 6);
  for (const std::string method :
       {"/tod.v1.ObstacleDiscovery/Detect", "/tod.v1.ObstacleDiscovery/GetModelInfo"}) {
    for (const std::string& bytes : {truncated_field, std::string("\xff\xff", 2)}) {
      const grpc::Status status = call(method, bytes);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << method;
      EXPECT_NE(status.error_message().find("malformed"), std::string::npos)
          << method << ": '" << status.error_message() << "'";
    }
  }
  // A malformed frame in a stream ends the stream with INVALID_ARGUMENT naming the frame.
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + 30s);
  grpc::CompletionQueue queue;
  auto stream = stub.PrepareCall(&context, "/tod.v1.ObstacleDiscovery/DetectStream", &queue);
  void* tag = nullptr;
  bool ok = false;
  auto step = [&] { ASSERT_TRUE(queue.Next(&tag, &ok)); };
  stream->StartCall(reinterpret_cast<void*>(1));
  step();
  grpc::Slice slice(truncated_field);
  stream->Write(grpc::ByteBuffer(&slice, 1), reinterpret_cast<void*>(2));
  step();
  stream->WritesDone(reinterpret_cast<void*>(3));
  step();
  grpc::Status stream_status;
  stream->Finish(&stream_status, reinterpret_cast<void*>(4));
  step();
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  EXPECT_EQ(stream_status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(stream_status.error_message().find("frame 0: malformed"), std::string::npos)
      << stream_status.error_message();
  // Well-formed requests still work through the same raw methods.
  client::TodGrpcClient grpc(server_->grpc_address());
  tod::v1::ModelInfo info;
  EXPECT_TRUE(grpc.GetModelInfo(&info).ok());
}

// Probe: GET/PUT on /v1/detect used to be 404, and errors inside the HTTP library were neither
// logged nor counted.
TEST_F(HttpHardeningTest, WrongMethodIs405WithAllowAndTransportErrorsAreCounted) {
  const double before = Refused(port(), "method_not_allowed");
  const auto get = http_->Get("/v1/detect");
  ASSERT_TRUE(get);
  EXPECT_EQ(get->status, 405);
  EXPECT_EQ(get->get_header_value("Allow"), "POST");
  const auto put = http_->Put("/v1/detect", testing::RoadPng(), "image/png");
  ASSERT_TRUE(put);
  EXPECT_EQ(put->status, 405);
  EXPECT_EQ(put->get_header_value("Allow"), "POST");
  const auto post_live = http_->Post("/v2/health/live", "", "text/plain");
  ASSERT_TRUE(post_live);
  EXPECT_EQ(post_live->status, 405);
  EXPECT_EQ(post_live->get_header_value("Allow"), "GET");
  EXPECT_NE(ErrorMessage(post_live->body).find("not allowed"), std::string::npos);
  EXPECT_EQ(Refused(port(), "method_not_allowed"), before + 3);

  const double malformed = Refused(port(), "malformed_request");
  RawConnection connection(port());
  ASSERT_TRUE(connection.Send("THIS IS NOT HTTP\r\n\r\n"));
  const auto response = connection.ReadResponse(15s);
  ASSERT_TRUE(response);
  EXPECT_EQ(response->status, 400);
  EXPECT_EQ(Refused(port(), "malformed_request"), malformed + 1);
  EXPECT_NE(server_->Log().find("malformed_request"), std::string::npos);
}

TEST(HttpHardeningOwnServerTest, ConnectionsPerClientAreCapped) {
  REQUIRE_MODEL();
  auto server = StartServer({"--http-max-connections-per-client", "4"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const std::string live = "GET /v2/health/live HTTP/1.1\r\nHost: t\r\n\r\n";
  // Four kept-alive connections, each answered once (so certainly admitted).
  std::vector<std::unique_ptr<RawConnection>> held;
  for (int i = 0; i < 4; ++i) {
    held.push_back(std::make_unique<RawConnection>(server->http_port()));
    ASSERT_TRUE(held.back()->Send(live));
    const auto response = held.back()->ReadResponse(15s);
    ASSERT_TRUE(response);
    ASSERT_EQ(response->status, 200);
  }
  RawConnection fifth(server->http_port());
  ASSERT_TRUE(fifth.connected());
  fifth.Send(live);
  const auto refused = fifth.ReadResponse(15s);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 503);
  EXPECT_EQ(refused->headers.count("retry-after"), 1u);
  EXPECT_NE(ErrorMessage(refused->body).find("too many connections"), std::string::npos);
  // A slot comes back once a connection closes (noticed asynchronously: bounded retries).
  held.pop_back();
  int status = 0;
  for (int attempt = 0; attempt < 100 && status != 200; ++attempt) {
    RawConnection again(server->http_port());
    if (again.Send(live)) {
      const auto response = again.ReadResponse(15s);
      status = response ? response->status : -1;
    }
    if (status != 200) std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(status, 200);
  held.clear();
  // The scrape needs a slot too; the server notices the closed connections asynchronously.
  std::string metrics;
  for (int attempt = 0; attempt < 100 && metrics.empty(); ++attempt) {
    metrics = ScrapeMetrics(server->http_port());
    if (metrics.empty()) std::this_thread::sleep_for(100ms);
  }
  // At least the fifth connection; retries made before a slot came back count too.
  EXPECT_GE(
      MetricValue(metrics, R"(tod_http_refused_total{reason="too_many_connections_per_client"})")
          .value_or(0),
      1)
      << metrics;
}

TEST(HttpHardeningOwnServerTest, BodyBytesInFlightShareOneBudget) {
  REQUIRE_MODEL();
  // Room for exactly one body of the maximum size.
  auto server =
      StartServer({"--max-image-bytes", "1000000", "--http-max-buffered-bytes", "1000000"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const std::string holder_header =
      "POST /v1/detect HTTP/1.1\r\nHost: t\r\nContent-Type: image/png\r\n"
      "Content-Length: 1000000\r\n\r\n";
  // Once the holder's header is read, its whole declared body is charged: any other body is
  // refused until the holder is done. The server's I/O threads read headers in no set order, so
  // a small request may be read first; it then holds 10 bytes, the holder is refused (503 before
  // its body) and the small request is admitted (400). Such a holder is replaced.
  const std::string small =
      "POST /v1/detect HTTP/1.1\r\nHost: t\r\nContent-Type: image/png\r\n"
      "Content-Length: 10\r\n\r\n0123456789";
  std::unique_ptr<RawConnection> holder;
  int status = 0;
  for (int attempt = 0; attempt < 100 && status != 503; ++attempt) {
    if (!holder || holder->Readable(0ms)) {  // none yet, or answered (refused) before its body
      holder = std::make_unique<RawConnection>(server->http_port());
      ASSERT_TRUE(holder->Send(holder_header));
      std::this_thread::sleep_for(50ms);
    }
    RawConnection other(server->http_port());
    if (other.Send(small)) {
      const auto response = other.ReadResponse(15s);
      status = response ? response->status : -1;
    }
    if (status != 503) std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(status, 503) << server->Log();
  // The holder finishes its body (not an image: 400) and gives the budget back.
  ASSERT_TRUE(holder->Send(std::string(1000000, 'x'))) << server->Log();
  const auto held = holder->ReadResponse(30s);
  ASSERT_TRUE(held);
  EXPECT_EQ(held->status, 400);
  // Admitted again (the budget comes back just after the holder's answer is written; bounded
  // retries): the 10 bytes are not an image.
  int after = 0;
  for (int attempt = 0; attempt < 100 && after != 400; ++attempt) {
    RawConnection again(server->http_port());
    if (again.Send(small)) {
      const auto response = again.ReadResponse(15s);
      after = response ? response->status : -1;
    }
    if (after != 400) std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(after, 400);
  EXPECT_GE(Refused(server->http_port(), "buffer_budget"), 1);
}

TEST(HttpHardeningOwnServerTest, SilentConnectionsAreClosedAtTheIdleTimeout) {
  REQUIRE_MODEL();
  auto server = StartServer({"--http-idle-timeout", "1"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  RawConnection silent(server->http_port());
  ASSERT_TRUE(silent.connected());
  // Closed by the server (EOF, no answer) long before this generous bound.
  ASSERT_TRUE(silent.Readable(30s));
  EXPECT_FALSE(silent.ReadResponse(5s));
  EXPECT_GE(Refused(server->http_port(), "idle_timeout"), 1);
}

// A client that sends valid requests but does not read the answers (or reads one byte a second)
// leaves each answer in the server's socket. Writing one answer has a deadline of its own
// (--http-write-timeout): when it passes, the connection is closed and its slot, in-flight count
// and body budget are free again; probes are answered all the while. Asserted through metrics
// polled with generous bounds, never through how long anything took.
void ExpectSlowReaderIsCutAtTheWriteDeadline(bool reads_a_byte_a_second) {
  REQUIRE_MODEL();
  // 10 s: long enough that probes are surely seen while the answer is held, even on a busy machine.
  auto server = StartServer({"--http-write-timeout", "10"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const int port = server->http_port();
  // A small receive window, so that unread answers back up into the server after a few of them.
  RawConnection reader(port, /*receive_buffer_bytes=*/4096);
  ASSERT_TRUE(reader.connected());
  const std::string png = testing::RoadPng();
  ASSERT_TRUE(
      reader.Send("POST /v1/detect?map=none HTTP/1.1\r\nHost: t\r\nContent-Type: "
                  "image/png\r\nContent-Length: " +
                  std::to_string(png.size()) + "\r\n\r\n" + png));
  // Then valid requests pipelined behind it, as long as the server reads them: it stops reading
  // when an answer no longer fits into the socket, which is the write the deadline must bound.
  const std::string scrape = "GET /metrics HTTP/1.1\r\nHost: t\r\n\r\n";
  httplib::Client probe("127.0.0.1", port);
  probe.set_connection_timeout(10s);
  probe.set_read_timeout(10s);
  std::string read_slowly;
  int probes_answered = 0;
  int probes_while_held = 0;  // answered while the reader's connection was full and not yet cut
  bool cut = false;
  uint64_t pipelined = 0;
  const auto give_up = std::chrono::steady_clock::now() + 120s;
  while (!cut && std::chrono::steady_clock::now() < give_up) {
    const std::optional<uint64_t> sent = reader.SendRepeatedWhileRoom(scrape, 64 * kMiB);
    if (!sent) break;  // the server closed the connection
    pipelined += *sent;
    if (reads_a_byte_a_second) {
      bool closed = false;
      if (const std::optional<char> byte = reader.ReadByte(0ms, &closed)) read_slowly += *byte;
      if (closed) break;
    }
    const auto live = probe.Get("/v2/health/live");
    ASSERT_TRUE(live && live->status == 200) << "liveness probe not answered";
    ++probes_answered;
    cut = Refused(port, "write_timeout") >= 1;
    if (!cut && *sent == 0) ++probes_while_held;
    std::this_thread::sleep_for(1s);
  }
  EXPECT_TRUE(server->WaitForMetric(R"(tod_http_refused_total{reason="write_timeout"})", 1, 60s))
      << "no write timeout after " << pipelined << " pipelined bytes";
  EXPECT_GE(probes_while_held, 1) << "no probe answered while the answers were held";
  EXPECT_TRUE(reader.WaitClosed(60s)) << "the server kept the connection";
  // What trickled through is the start of the detection's answer.
  const std::string status_line = "HTTP/1.1 200 OK";
  EXPECT_EQ(read_slowly.substr(0, status_line.size()),
            status_line.substr(0, std::min(read_slowly.size(), status_line.size())));
  // Nothing held: no request in flight, only the scraper's own connection open (closed
  // connections are noticed asynchronously: polled, bounded).
  std::string metrics;
  for (int attempt = 0; attempt < 300; ++attempt) {
    metrics = ScrapeMetrics(port);
    if (MetricValue(metrics, "tod_http_open_connections").value_or(-1) <= 1 &&
        MetricValue(metrics, "tod_in_flight_requests").value_or(-1) == 0) {
      break;
    }
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_LE(MetricValue(metrics, "tod_http_open_connections").value_or(-1), 1) << metrics;
  EXPECT_EQ(MetricValue(metrics, "tod_in_flight_requests").value_or(-1), 0) << metrics;
  EXPECT_NE(server->Log().find("write_timeout"), std::string::npos);
  // And the server serves as before.
  probe.set_read_timeout(60s);
  const auto detect = probe.Post("/v1/detect?map=none", png, "image/png");
  ASSERT_TRUE(detect);
  EXPECT_EQ(detect->status, 200) << detect->body;
}

TEST(HttpHardeningOwnServerTest, ClientNotReadingItsAnswersIsCutAtTheWriteDeadline) {
  ExpectSlowReaderIsCutAtTheWriteDeadline(/*reads_a_byte_a_second=*/false);
}

TEST(HttpHardeningOwnServerTest, ClientReadingOneByteASecondIsCutAtTheWriteDeadline) {
  ExpectSlowReaderIsCutAtTheWriteDeadline(/*reads_a_byte_a_second=*/true);
}

}  // namespace
}  // namespace tod::server
