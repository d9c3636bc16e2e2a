// End-to-end: the real tod_server with the real pipeline (the tiny bundle of the CTest fixture,
// $TOD_TEST_MODEL) on loopback ports, driven through the real client library, tod_client,
// tod_load and plain HTTP.
#include <gtest/gtest.h>
#include <httplib.h>
#include <signal.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "client/tod_grpc_client.h"
#include "tests/service/server_harness.h"
#include "tests/service/shared_server_test.h"
#include "tests/service/test_images.h"
#include "tests/test_env.h"

namespace tod::server {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::MetricValue;
using testing::RunCommand;
using testing::ScrapeMetrics;
using testing::ServerProcess;
using testing::TestModel;

// Limits the shared server runs with; the error tests go just over them.
constexpr int kMaxBytes = 400'000;
constexpr int kMaxPixels = 700 * 400;

tod::v1::DetectRequest MakeRequest(const std::string& image, const std::string& frame_id = "") {
  tod::v1::DetectRequest request;
  request.set_image(image);
  request.set_frame_id(frame_id);
  return request;
}

httplib::Result PostImage(httplib::Client& client, const std::string& path, const std::string& body,
                          const std::string& type = "image/png") {
  return client.Post(path.c_str(), body, type.c_str());
}

std::string ErrorMessage(const httplib::Result& result) {
  if (!result) return "";
  const nlohmann::json json = nlohmann::json::parse(result->body, nullptr, false);
  return json.is_discarded() ? "" : json["error"].value("message", "");
}

// One server shared by the functional tests of this suite.
class ServiceE2ETest : public testing::SharedServerTest<ServiceE2ETest> {
 public:
  static std::vector<std::string> ServerArgs() {
    return {"--workers",
            "2",
            "--queue",
            "16",
            "--max-image-bytes",
            std::to_string(kMaxBytes),
            "--max-image-pixels",
            std::to_string(kMaxPixels),
            "--log-format",
            "json"};
  }

 protected:
  void SetUp() override {
    SharedServerTest::SetUp();
    if (HasFatalFailure()) return;
    http_ = std::make_unique<httplib::Client>("127.0.0.1", server_->http_port());
    http_->set_read_timeout(60s);
    grpc_ = std::make_unique<client::TodGrpcClient>(server_->grpc_address());
  }
  void ExpectStillServes() {
    tod::v1::DetectResponse response;
    const grpc::Status status = grpc_->Detect(MakeRequest(testing::RoadPng()), &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    const auto live = http_->Get("/v2/health/ready");
    ASSERT_TRUE(live);
    EXPECT_EQ(live->status, 200);
  }

  std::unique_ptr<httplib::Client> http_;
  std::unique_ptr<client::TodGrpcClient> grpc_;
};

TEST_F(ServiceE2ETest, GrpcAndRestAgreeOnASyntheticFrame) {
  const std::string frame = testing::RoadPng();
  tod::v1::DetectResponse grpc_response;
  const grpc::Status status = grpc_->Detect(MakeRequest(frame, "f1"), &grpc_response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(grpc_response.frame_id(), "f1");
  EXPECT_EQ(grpc_response.width(), 320);
  EXPECT_EQ(grpc_response.height(), 160);
  EXPECT_FALSE(grpc_response.model_version().empty());
  EXPECT_EQ(grpc_response.probability_map().width(), 320);
  ASSERT_FALSE(grpc_response.probability_map().png().empty());
  ASSERT_GE(grpc_response.timings_size(), 3);
  EXPECT_EQ(grpc_response.timings(0).stage(), "queue");
  EXPECT_EQ(grpc_response.timings(1).stage(), "decode");
  EXPECT_EQ(grpc_response.timings(grpc_response.timings_size() - 1).stage(), "encode_map");

  const auto rest = PostImage(*http_, "/v1/detect?frame_id=f1", frame);
  ASSERT_TRUE(rest);
  ASSERT_EQ(rest->status, 200) << rest->body;
  EXPECT_EQ(rest->get_header_value("Content-Type"), "application/json");
  const nlohmann::json json = nlohmann::json::parse(rest->body);
  EXPECT_EQ(json["frame_id"], "f1");
  EXPECT_EQ(json["model_version"], grpc_response.model_version());
  EXPECT_EQ(json["width"], 320);
  // The pipeline is deterministic: same obstacles, same proposals, same map.
  ASSERT_EQ(json["obstacles"].size(), static_cast<size_t>(grpc_response.obstacles_size()));
  for (int i = 0; i < grpc_response.obstacles_size(); ++i) {
    EXPECT_EQ(json["obstacles"][i]["box"]["x"], grpc_response.obstacles(i).box().x());
    EXPECT_EQ(json["obstacles"][i]["area"], grpc_response.obstacles(i).area());
  }
  ASSERT_EQ(json["proposals"].size(), static_cast<size_t>(grpc_response.proposals_size()));
  for (int i = 0; i < grpc_response.proposals_size(); ++i) {
    EXPECT_EQ(json["proposals"][i]["box"]["y"], grpc_response.proposals(i).box().y());
    EXPECT_FLOAT_EQ(json["proposals"][i]["fused"].get<float>(), grpc_response.proposals(i).fused());
  }
  const auto map = PostImage(*http_, "/v1/probability-map", frame);
  ASSERT_TRUE(map);
  ASSERT_EQ(map->status, 200);
  EXPECT_EQ(map->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(map->body, grpc_response.probability_map().png());
  const cv::Mat decoded =
      cv::imdecode(std::vector<uchar>(map->body.begin(), map->body.end()), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(decoded.size(), cv::Size(320, 160));

  // map=none / MAP_FORMAT_NONE: no map bytes.
  const auto no_map = PostImage(*http_, "/v1/detect?map=none&max_proposals=2", frame);
  ASSERT_TRUE(no_map);
  ASSERT_EQ(no_map->status, 200);
  const nlohmann::json no_map_json = nlohmann::json::parse(no_map->body);
  EXPECT_FALSE(no_map_json.contains("probability_map")) << "no map requested, none sent";
  EXPECT_LE(no_map_json["proposals"].size(), 2u);
}

// Parity: one frame through `tod detect`, gRPC and REST gives the same non-empty proposals, the
// same obstacles and the same map (the server and the tool share the detector, not a copy of it).
TEST_F(ServiceE2ETest, TheToolGrpcAndRestGiveTheSameDetections) {
  const std::string frame = testing::RoadPng();
  const std::string dir = testing::MakeTempDir("tod_parity");
  std::ofstream(dir + "/frame.png", std::ios::binary) << frame;
  const auto tool = RunCommand({testing::BinaryPath("tod"), "detect", "--model", TestModel(),
                                "--out", dir + "/out", dir + "/frame.png"});
  ASSERT_EQ(tool.exit_code, 0) << tool.output;
  std::ifstream tool_json_file(dir + "/out/frame.json");
  const nlohmann::json tool_json = nlohmann::json::parse(tool_json_file);
  const cv::Mat tool_map = cv::imread(dir + "/out/frame_prob.png", cv::IMREAD_UNCHANGED);

  tod::v1::DetectResponse grpc_response;
  const grpc::Status status = grpc_->Detect(MakeRequest(frame), &grpc_response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const auto rest = PostImage(*http_, "/v1/detect", frame);
  ASSERT_TRUE(rest);
  ASSERT_EQ(rest->status, 200) << rest->body;
  const nlohmann::json rest_json = nlohmann::json::parse(rest->body);

  ASSERT_GT(grpc_response.proposals_size(), 0) << "nothing to compare";
  ASSERT_GE(tool_json["proposals"].size(), static_cast<size_t>(grpc_response.proposals_size()));
  ASSERT_EQ(rest_json["proposals"].size(), static_cast<size_t>(grpc_response.proposals_size()));
  for (int i = 0; i < grpc_response.proposals_size(); ++i) {
    const tod::v1::Proposal& served = grpc_response.proposals(i);
    const nlohmann::json& listed = tool_json["proposals"][i];
    EXPECT_EQ(listed["x"], served.box().x()) << i;
    EXPECT_EQ(listed["y"], served.box().y()) << i;
    EXPECT_EQ(listed["w"], served.box().w()) << i;
    EXPECT_EQ(listed["h"], served.box().h()) << i;
    EXPECT_FLOAT_EQ(listed["score"].get<float>(), served.fused()) << i;
    EXPECT_EQ(rest_json["proposals"][i]["box"]["x"], served.box().x()) << i;
    EXPECT_FLOAT_EQ(rest_json["proposals"][i]["fused"].get<float>(), served.fused()) << i;
  }
  EXPECT_EQ(tool_json["obstacles"].size(), static_cast<size_t>(grpc_response.obstacles_size()));
  EXPECT_EQ(rest_json["obstacles"].size(), static_cast<size_t>(grpc_response.obstacles_size()));

  const std::string& png = grpc_response.probability_map().png();
  const cv::Mat served_map =
      cv::imdecode(std::vector<uchar>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(tool_map.empty());
  ASSERT_EQ(served_map.size(), tool_map.size());
  EXPECT_GT(cv::countNonZero(tool_map), 0) << "an empty map proves nothing";
  EXPECT_EQ(cv::norm(served_map, tool_map, cv::NORM_INF), 0) << "the maps differ";
  fs::remove_all(dir);
}

TEST_F(ServiceE2ETest, StreamAnswersEveryFrameInOrder) {
  std::vector<tod::v1::DetectRequest> requests;
  for (int i = 0; i < 4; ++i) {
    requests.push_back(MakeRequest(
        testing::Encode(testing::RoadFrame(320, 160, 40 + 50 * i, 100), i % 2 ? ".jpg" : ".png"),
        "cam0-" + std::to_string(i)));
  }
  std::vector<std::string> ids;
  const grpc::Status status = grpc_->DetectStream(
      requests,
      [&](const tod::v1::DetectResponse& response) { ids.push_back(response.frame_id()); });
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(ids, (std::vector<std::string>{"cam0-0", "cam0-1", "cam0-2", "cam0-3"}));
}

TEST_F(ServiceE2ETest, ClientToolWritesOutputsAndReportsHealth) {
  const std::string dir = testing::MakeTempDir("tod_client_e2e");
  fs::create_directories(dir + "/in");
  std::ofstream(dir + "/in/a.png", std::ios::binary) << testing::RoadPng();
  std::ofstream(dir + "/in/b.jpg", std::ios::binary)
      << testing::Encode(testing::RoadFrame(), ".jpg");
  const std::string client = testing::BinaryPath("tod_client");
  for (const std::string command : {"detect", "stream"}) {
    const auto run = RunCommand({client, command, "--addr", server_->grpc_address(), dir + "/in",
                                 "--out", dir + "/" + command});
    ASSERT_EQ(run.exit_code, 0) << run.output;
    for (const std::string stem : {"a", "b"}) {
      const std::string base = dir + "/" + command + "/" + stem;
      ASSERT_TRUE(fs::exists(base + ".json")) << base;
      const nlohmann::json json = nlohmann::json::parse(std::ifstream(base + ".json"));
      EXPECT_EQ(json["width"], 320);
      const cv::Mat map = cv::imread(base + ".map.png", cv::IMREAD_UNCHANGED);
      EXPECT_EQ(map.size(), cv::Size(320, 160));
      const cv::Mat overlay = cv::imread(base + ".overlay.png");
      EXPECT_EQ(overlay.size(), cv::Size(320, 160));
    }
  }
  const auto health = RunCommand({client, "health", "--addr", server_->grpc_address()});
  EXPECT_EQ(health.exit_code, 0) << health.output;
  EXPECT_NE(health.output.find("SERVING"), std::string::npos);
  const auto info = RunCommand({client, "info", "--addr", server_->grpc_address()});
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("\"generation\": 1"), std::string::npos) << info.output;
  // Nobody listens on this port: health must fail (exit 1), not hang or crash.
  const auto unreachable = RunCommand(
      {client, "health", "--addr", "127.0.0.1:" + std::to_string(testing::FreeLoopbackPort())});
  EXPECT_EQ(unreachable.exit_code, 1) << unreachable.output;
}

TEST_F(ServiceE2ETest, ModelInfoHealthAndMetrics) {
  tod::v1::ModelInfo info;
  ASSERT_TRUE(grpc_->GetModelInfo(&info).ok());
  EXPECT_EQ(info.generation(), 1);
  // The bundle's name, never the server's path.
  EXPECT_EQ(info.model_dir(), fs::path(TestModel()).filename().string());
  EXPECT_EQ(info.model_dir(), info.name());
  EXPECT_EQ(info.manifest_json().find(TestModel()), std::string::npos);
  EXPECT_FALSE(info.manifest_json().empty());
  const auto rest = http_->Get("/v1/model");
  ASSERT_TRUE(rest);
  ASSERT_EQ(rest->status, 200);
  const nlohmann::json json = nlohmann::json::parse(rest->body);
  EXPECT_EQ(json["version"], info.version());
  EXPECT_EQ(json["name"], info.name());
  EXPECT_EQ(rest->body.find(TestModel()), std::string::npos) << rest->body;

  grpc::health::v1::HealthCheckResponse health;
  ASSERT_TRUE(grpc_->Health("", &health).ok());
  EXPECT_EQ(health.status(), grpc::health::v1::HealthCheckResponse::SERVING);
  ASSERT_TRUE(grpc_->Health("tod.v1.ObstacleDiscovery", &health).ok());
  EXPECT_EQ(health.status(), grpc::health::v1::HealthCheckResponse::SERVING);
  EXPECT_EQ(http_->Get("/v2/health/live")->status, 200);
  EXPECT_EQ(http_->Get("/v2/health/ready")->status, 200);

  tod::v1::DetectResponse response;
  ASSERT_TRUE(grpc_->Detect(MakeRequest(testing::RoadPng()), &response).ok());
  const std::string metrics = ScrapeMetrics(server_->http_port());
  EXPECT_GE(MetricValue(metrics, R"(tod_requests_total{code="OK",protocol="grpc"})").value_or(0), 1)
      << metrics;
  EXPECT_NE(metrics.find("tod_request_duration_seconds_bucket"), std::string::npos);
  EXPECT_NE(metrics.find("tod_queue_duration_seconds_count"), std::string::npos);
  EXPECT_NE(metrics.find(R"(tod_stage_duration_seconds_count{stage="decode"})"), std::string::npos);
  EXPECT_NE(metrics.find("tod_queue_depth"), std::string::npos);
  EXPECT_NE(metrics.find("tod_in_flight_requests"), std::string::npos);
  EXPECT_NE(metrics.find("tod_model_info{"), std::string::npos);
  EXPECT_NE(metrics.find(R"(generation="1")"), std::string::npos);
}

// The frame budget: a request may lower the server's --frame-budget-ms; a budget the frame
// cannot meet degrades its proposals, the answer is still 200 / OK and says so, and the metric
// counts it. (1 ms is spent before the window scan starts on any machine.)
TEST_F(ServiceE2ETest, AFrameOverItsBudgetDegradesSaysSoAndIsCounted) {
  const std::string frame = testing::RoadPng();
  const auto rest = PostImage(*http_, "/v1/detect?map=none&budget_ms=1", frame);
  ASSERT_TRUE(rest);
  ASSERT_EQ(rest->status, 200) << rest->body;
  const nlohmann::json json = nlohmann::json::parse(rest->body);
  EXPECT_EQ(json["degraded"], true) << rest->body;
  ASSERT_TRUE(json["degraded_stages"].is_array());
  const auto stages = json["degraded_stages"].get<std::vector<std::string>>();
  EXPECT_NE(std::find(stages.begin(), stages.end(), "proposals"), stages.end()) << rest->body;

  tod::v1::DetectRequest request = MakeRequest(frame);
  request.mutable_options()->set_budget_ms(1);
  tod::v1::DetectResponse response;
  ASSERT_TRUE(grpc_->Detect(request, &response).ok());
  EXPECT_TRUE(response.degraded());
  EXPECT_NE(
      std::find(response.degraded_stages().begin(), response.degraded_stages().end(), "proposals"),
      response.degraded_stages().end());

  const std::string metrics = ScrapeMetrics(server_->http_port());
  EXPECT_GE(MetricValue(metrics, R"(tod_frames_degraded_total{stage="proposals"})").value_or(0), 2)
      << metrics;
  EXPECT_TRUE(MetricValue(metrics, R"(tod_frames_degraded_total{stage="occlusion"})")) << metrics;

  // Out of range: refused before any work, naming the option.
  for (const std::string query : {"budget_ms=0", "budget_ms=600001", "budget_ms=-3"}) {
    const auto refused = PostImage(*http_, "/v1/detect?" + query, frame);
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, 400) << query;
    EXPECT_NE(ErrorMessage(refused).find("budget_ms"), std::string::npos) << refused->body;
  }
  request.mutable_options()->set_budget_ms(700'000);
  EXPECT_EQ(grpc_->Detect(request, &response).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(ServiceE2ETest, TheCalibratedMapIsBoundedByTheBestBoxsCalibratedScore) {
  const std::string frame = testing::RoadPng();
  tod::v1::ModelInfo info;
  ASSERT_TRUE(grpc_->GetModelInfo(&info).ok());
  const nlohmann::json calibration =
      nlohmann::json::parse(info.manifest_json())["params"]["obstacle_calibration"];
  ASSERT_TRUE(calibration["fitted"].get<bool>()) << calibration.dump();
  const auto peak_of = [](const std::string& png) {
    const cv::Mat map =
        cv::imdecode(std::vector<uchar>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
    double peak = -1;
    if (!map.empty()) cv::minMaxLoc(map, nullptr, &peak);
    return peak;
  };

  tod::v1::DetectRequest request = MakeRequest(frame);
  request.mutable_options()->set_map_kind(tod::v1::MAP_KIND_CALIBRATED);
  tod::v1::DetectResponse response;
  ASSERT_TRUE(grpc_->Detect(request, &response).ok());
  EXPECT_EQ(response.probability_map().kind(), tod::v1::MAP_KIND_CALIBRATED);
  ASSERT_GE(response.proposals_size(), 1);
  const double best = response.proposals(0).fused();  // proposals come best first
  ASSERT_GT(best, 0.0);
  const double expected = 255.0 / (1.0 + std::exp(-(calibration["slope"].get<double>() * best +
                                                    calibration["intercept"].get<double>())));
  // A pixel holds a box's calibrated score times the share of its superpixel the box holds, so
  // no pixel exceeds the best box's calibrated score (8-bit rounding aside), and the pixels of
  // the best box are not zero. It is a probability, not divided by the frame's maximum (255).
  const double peak = peak_of(response.probability_map().png());
  EXPECT_LE(peak, expected + 1.0);
  EXPECT_GT(peak, 0.0);
  EXPECT_LT(expected, 254.0);

  const auto rest = PostImage(*http_, "/v1/detect?map_kind=calibrated", frame);
  ASSERT_TRUE(rest);
  ASSERT_EQ(rest->status, 200) << rest->body;
  EXPECT_EQ(nlohmann::json::parse(rest->body)["probability_map"]["kind"], "MAP_KIND_CALIBRATED");
  const auto normalized = PostImage(*http_, "/v1/probability-map?map_kind=normalized", frame);
  ASSERT_TRUE(normalized);
  ASSERT_EQ(normalized->status, 200);
  EXPECT_EQ(peak_of(normalized->body), 255.0);  // the paper's map: divided by its maximum

  const auto refused = PostImage(*http_, "/v1/detect?map_kind=sum", frame);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 400);
  EXPECT_NE(ErrorMessage(refused).find("map_kind"), std::string::npos) << refused->body;
}

// RGB and RGBA PNGs take the plain-PNG decoder, a palette PNG libpng; the same pixels give the
// same detections whichever decoder ran, and a damaged chunk is the client's error.
TEST_F(ServiceE2ETest, EveryPngLayoutGivesTheSameDetections) {
  const cv::Mat3b road = testing::RoadFrame(320, 160);
  cv::Mat rgba;
  cv::cvtColor(road, rgba, cv::COLOR_BGR2BGRA);
  const std::string rgb_png = testing::Encode(road, ".png");
  const std::string rgba_png = testing::Encode(rgba, ".png");
  const auto detect = [&](const std::string& png) {
    const auto result = PostImage(*http_, "/v1/detect?map=none", png);
    EXPECT_TRUE(result && result->status == 200) << (result ? result->body : "no answer");
    return result ? nlohmann::json::parse(result->body)["proposals"] : nlohmann::json();
  };
  const nlohmann::json from_rgb = detect(rgb_png);
  ASSERT_FALSE(from_rgb.empty());
  EXPECT_EQ(detect(rgba_png), from_rgb);
  // The same frame through libpng: grey levels only, so a grey PNG holds it exactly.
  cv::Mat1b grey;
  cv::cvtColor(road, grey, cv::COLOR_BGR2GRAY);
  cv::Mat3b grey_bgr;
  cv::cvtColor(grey, grey_bgr, cv::COLOR_GRAY2BGR);
  EXPECT_EQ(detect(testing::Encode(grey, ".png")), detect(testing::Encode(grey_bgr, ".png")));

  std::string damaged = rgb_png;
  damaged[damaged.size() - 20] ^= 0x01;  // inside the last IDAT chunk's data
  const auto refused = PostImage(*http_, "/v1/detect", damaged);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 400);
  EXPECT_NE(ErrorMessage(refused).find("CRC"), std::string::npos) << refused->body;
  ExpectStillServes();
}

TEST_F(ServiceE2ETest, RestErrorsHaveCodesAndMessages) {
  struct Case {
    std::string path;
    std::string body;
    std::string type;
    int status;
    std::string message_part;
  };
  const std::string png = testing::RoadPng();
  const std::vector<Case> cases = {
      {"/v1/detect", "", "image/png", 400, "empty"},
      {"/v1/detect", "this is not an image", "image/jpeg", 400, "not a JPEG, PNG or WebP"},
      {"/v1/detect", png.substr(0, png.size() / 2), "image/png", 400, "decode"},
      {"/v1/detect", png, "text/plain", 415, "Content-Type"},
      {"/v1/detect", std::string(kMaxBytes + 10, 'x'), "image/png", 413, "bytes"},
      {"/v1/detect", testing::RoadPng(701, 400), "image/png", 413, "pixels"},
      {"/v1/detect?obstacle_threshold=2", png, "image/png", 400, "obstacle_threshold"},
      {"/v1/detect?max_proposals=abc", png, "image/png", 400, "max_proposals"},
      {"/v1/detect?map=jpeg", png, "image/png", 400, "map"},
      {"/v1/probability-map", "", "image/png", 400, "empty"},
      {"/v1/nothing-here", png, "image/png", 404, "no such endpoint"},
  };
  for (const Case& c : cases) {
    const auto result = PostImage(*http_, c.path, c.body, c.type);
    ASSERT_TRUE(result) << c.path;
    EXPECT_EQ(result->status, c.status) << c.path << " " << c.type << ": " << result->body;
    EXPECT_NE(ErrorMessage(result).find(c.message_part), std::string::npos)
        << c.path << ": " << result->body;
  }
  ExpectStillServes();
}

TEST_F(ServiceE2ETest, GrpcErrorsHaveCodesAndMessages) {
  tod::v1::DetectResponse response;
  grpc::Status status = grpc_->Detect(MakeRequest(""), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("empty"), std::string::npos);

  status = grpc_->Detect(MakeRequest("garbage bytes"), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  status = grpc_->Detect(MakeRequest(std::string(kMaxBytes + 10, 'x')), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(status.error_message().find("over the limit"), std::string::npos)
      << status.error_message();

  status = grpc_->Detect(MakeRequest(testing::RoadPng(701, 400)), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(status.error_message().find("pixels"), std::string::npos);

  tod::v1::DetectRequest bad_option = MakeRequest(testing::RoadPng());
  bad_option.mutable_options()->set_obstacle_threshold(-0.5f);
  status = grpc_->Detect(bad_option, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  // A bad frame in a stream ends that stream with the frame's status; the server goes on.
  std::vector<tod::v1::DetectRequest> stream = {MakeRequest(testing::RoadPng(), "ok"),
                                                MakeRequest("junk", "bad")};
  int answered = 0;
  status = grpc_->DetectStream(stream, [&](const tod::v1::DetectResponse&) { ++answered; });
  EXPECT_EQ(answered, 1);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("frame 1"), std::string::npos) << status.error_message();
  ExpectStillServes();
}

TEST_F(ServiceE2ETest, LoadGeneratorReportsGrpcAndHttp) {
  const std::string dir = testing::MakeTempDir("tod_load_e2e");
  std::ofstream(dir + "/a.png", std::ios::binary) << testing::RoadPng();
  std::ofstream(dir + "/b.jpg", std::ios::binary) << testing::Encode(testing::RoadFrame(), ".jpg");
  const std::string load = testing::BinaryPath("tod_load");
  const std::vector<std::vector<std::string>> runs = {
      {load, "--addr", server_->grpc_address(), "--images", dir, "--concurrency", "2", "--duration",
       "1", "--warmup", "0.2", "--json", dir + "/grpc.json"},
      {load, "--addr", "127.0.0.1:" + std::to_string(server_->http_port()), "--http", "--images",
       dir, "--rate", "10", "--duration", "1", "--warmup", "0", "--json", dir + "/http.json"}};
  for (const auto& argv : runs) {
    const auto run = RunCommand(argv);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("p99"), std::string::npos) << run.output;
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(argv.back()));
    EXPECT_GT(report["requests"].get<int>(), 0);
    EXPECT_EQ(report["requests"], report["succeeded"]) << report.dump();
    EXPECT_GT(report["latency_ms"]["p50"].get<double>(), 0);
    EXPECT_LE(report["latency_ms"]["p50"].get<double>(), report["latency_ms"]["max"].get<double>());
  }
  const nlohmann::json open_loop = nlohmann::json::parse(std::ifstream(dir + "/http.json"));
  EXPECT_EQ(open_loop["mode"], "open");
  EXPECT_EQ(open_loop["codes"]["200"], open_loop["requests"]);
  EXPECT_EQ(open_loop["requests"], 10);  // 10/s for 1 s, every scheduled request answered
}

}  // namespace
}  // namespace tod::server
