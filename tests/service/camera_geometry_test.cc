// Self-calibration through the server (issue 48): the geometry a detection stood on is in every
// response (gRPC and REST), a camera_id accumulates one horizon estimate over its frames, a
// DetectStream is one camera, a bad camera_id is refused on both protocols, a shifted frame moves
// the served horizon by the shift, and the server keeps at most --max-cameras cameras and forgets
// the idle ones. The real tod_server with the fixture's tiny bundle (which tod train gave a
// horizon reference) on the fixture's synthetic frames, whose lines give most frames an estimate.
#include <gtest/gtest.h>
#include <httplib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
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
using testing::ServerProcess;
using testing::TestModel;

// The fixture's synthetic test frames (640 x 320), sorted: one camera's frames.
std::vector<std::string> FixtureFrames() {
  std::vector<fs::path> paths;
  const fs::path dir = fs::path(tod::testing_env::TestData()) / "leftImg8bit" / "test";
  if (!fs::exists(dir)) return {};
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.path().extension() == ".png") paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  std::vector<std::string> frames;
  for (const fs::path& path : paths) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    frames.push_back(bytes.str());
  }
  return frames;
}

nlohmann::json PostDetect(httplib::Client& http, const std::string& query, const std::string& png,
                          int* status_out = nullptr) {
  const std::string path = "/v1/detect?map=none&max_proposals=1" + query;
  const auto result = http.Post(path.c_str(), png, "image/png");
  if (!result) return {};
  if (status_out != nullptr) *status_out = result->status;
  return nlohmann::json::parse(result->body, nullptr, false);
}

tod::v1::DetectRequest Request(const std::string& image, const std::string& camera_id = "") {
  tod::v1::DetectRequest request;
  request.set_image(image);
  request.set_camera_id(camera_id);
  request.mutable_options()->set_map_format(tod::v1::MAP_FORMAT_NONE);
  return request;
}

class CameraGeometryTest : public testing::SharedServerTest<CameraGeometryTest> {
 public:
  // No frame budget: on a busy machine a degraded stage must not decide what is asserted.
  static std::vector<std::string> ServerArgs() {
    return {"--workers", "2", "--frame-budget-ms", "0"};
  }

 protected:
  void SetUp() override {
    SharedServerTest::SetUp();
    if (HasFatalFailure()) return;
    frames_ = FixtureFrames();
    ASSERT_GE(frames_.size(), 4u) << "the fixture's test frames";
    frames_.resize(4);
    http_ = std::make_unique<httplib::Client>("127.0.0.1", server_->http_port());
    http_->set_read_timeout(120s);
    grpc_ = std::make_unique<client::TodGrpcClient>(server_->grpc_address());
  }

  std::vector<std::string> frames_;
  std::unique_ptr<httplib::Client> http_;
  std::unique_ptr<client::TodGrpcClient> grpc_;
};

TEST_F(CameraGeometryTest, RestCameraIdAccumulatesOneEstimateAndIsCounted) {
  const double camera_frames_before =
      MetricValue(server_->Metrics(), "tod_geometry_total{source=\"camera\"}").value_or(0);
  long long previous_frames = 0;
  for (const std::string& frame : frames_) {
    int status = 0;
    const nlohmann::json json = PostDetect(*http_, "&camera_id=rest-cam", frame, &status);
    ASSERT_EQ(status, 200) << json.dump();
    const nlohmann::json& geometry = json["geometry"];
    EXPECT_EQ(geometry["source"], "camera") << geometry.dump();
    const long long frames = geometry.value("camera_frames", 0LL);
    EXPECT_GE(frames, previous_frames) << geometry.dump();
    previous_frames = frames;
    for (const char* key : {"horizon_row", "bundle_horizon_row", "road_region"})
      EXPECT_TRUE(geometry.contains(key)) << key << " in " << geometry.dump();
  }
  EXPECT_GE(previous_frames, 3) << "the synthetic camera's lines give most frames an estimate";

  const std::string metrics = server_->Metrics();
  EXPECT_GE(MetricValue(metrics, "tod_cameras_tracked").value_or(0), 1) << metrics;
  EXPECT_GE(MetricValue(metrics, "tod_geometry_total{source=\"camera\"}").value_or(0),
            camera_frames_before + 4)
      << metrics;
}

// gRPC frames of one camera_id share the estimate the REST frames of that id built: one registry.
TEST_F(CameraGeometryTest, GrpcAndRestShareACamerasEstimate) {
  long long rest_frames = 0;
  for (const std::string& frame : frames_)
    rest_frames =
        PostDetect(*http_, "&camera_id=shared-cam", frame)["geometry"].value("camera_frames", 0LL);
  ASSERT_GE(rest_frames, 3);
  tod::v1::DetectResponse response;
  const grpc::Status status = grpc_->Detect(Request(frames_[0], "shared-cam"), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.geometry().source(), "camera");
  EXPECT_GE(response.geometry().camera_frames(), rest_frames) << response.geometry().DebugString();
  EXPECT_TRUE(response.geometry().has_horizon_row());
}

TEST_F(CameraGeometryTest, AStreamIsOneCameraWhoseEstimateGrows) {
  std::vector<tod::v1::DetectRequest> requests;
  for (const std::string& frame : frames_) requests.push_back(Request(frame));
  std::vector<tod::v1::Geometry> geometries;
  const grpc::Status status = grpc_->DetectStream(
      requests,
      [&](const tod::v1::DetectResponse& response) { geometries.push_back(response.geometry()); });
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(geometries.size(), frames_.size());
  for (size_t i = 1; i < geometries.size(); ++i) {
    EXPECT_GE(geometries[i].camera_frames(), geometries[i - 1].camera_frames()) << i;
  }
  EXPECT_EQ(geometries.back().source(), "camera") << geometries.back().DebugString();
  EXPECT_GE(geometries.back().camera_frames(), 3);

  // A second stream is another camera: its estimate starts again.
  std::vector<tod::v1::Geometry> second;
  ASSERT_TRUE(grpc_
                  ->DetectStream({Request(frames_[0])},
                                 [&](const tod::v1::DetectResponse& response) {
                                   second.push_back(response.geometry());
                                 })
                  .ok());
  ASSERT_EQ(second.size(), 1u);
  EXPECT_LE(second[0].camera_frames(), 1);
}

// Without calibration the bundle's geometry is used unmoved, and the response says so.
TEST_F(CameraGeometryTest, CalibrateFalseKeepsTheBundlesGeometry) {
  int status = 0;
  const nlohmann::json json = PostDetect(*http_, "&calibrate=false", frames_[0], &status);
  ASSERT_EQ(status, 200) << json.dump();
  EXPECT_EQ(json["geometry"]["source"], "bundle") << json["geometry"].dump();
  EXPECT_EQ(json["geometry"].value("shift_rows", 0.0), 0.0);

  tod::v1::DetectRequest request = Request(frames_[0]);
  request.mutable_options()->set_calibrate(false);
  tod::v1::DetectResponse response;
  ASSERT_TRUE(grpc_->Detect(request, &response).ok());
  EXPECT_EQ(response.geometry().source(), "bundle");
  EXPECT_EQ(response.geometry().shift_rows(), 0.0);

  const auto bad = http_->Post("/v1/detect?calibrate=maybe", frames_[0], "image/png");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400) << bad->body;
}

// Both protocols refuse what cannot name a camera, with the reason, and go on serving.
TEST_F(CameraGeometryTest, ABadCameraIdIsRefusedOnBothProtocols) {
  const std::string too_long(129, 'c');
  for (const std::string& query : {"&camera_id=" + too_long, std::string("&camera_id=two%20words"),
                                   std::string("&camera_id=tab%09id")}) {
    int status = 0;
    const nlohmann::json json = PostDetect(*http_, query, frames_[0], &status);
    EXPECT_EQ(status, 400) << query;
    EXPECT_EQ(json["error"].value("code", ""), "INVALID_ARGUMENT") << json.dump();
    EXPECT_NE(json["error"].value("message", "").find("camera_id"), std::string::npos)
        << json.dump();
  }
  tod::v1::DetectResponse response;
  grpc::Status refused = grpc_->Detect(Request(frames_[0], too_long), &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(refused.error_message().find("camera_id"), std::string::npos)
      << refused.error_message();

  // 128 bytes is the limit, not over it.
  const grpc::Status ok = grpc_->Detect(Request(frames_[0], std::string(128, 'c')), &response);
  EXPECT_TRUE(ok.ok()) << ok.error_message();
}

// A camera mounted lower sees the road higher in the frame: the frame moved up by a tenth of its
// height is served on a horizon that moved by that much (each frame calibrated alone).
TEST_F(CameraGeometryTest, AShiftedFrameMovesTheServedHorizonByTheShift) {
  const std::string& original = frames_[0];
  const cv::Mat frame =
      cv::imdecode(std::vector<uchar>(original.begin(), original.end()), cv::IMREAD_COLOR);
  const int shift = frame.rows / 10;
  cv::Mat shifted;
  cv::copyMakeBorder(frame.rowRange(shift, frame.rows), shifted, 0, shift, 0, 0,
                     cv::BORDER_REPLICATE);
  std::vector<double> rows;
  for (const std::string& png : {original, testing::Encode(shifted, ".png")}) {
    int status = 0;
    const nlohmann::json json = PostDetect(*http_, "", png, &status);
    ASSERT_EQ(status, 200) << json.dump();
    ASSERT_EQ(json["geometry"]["source"], "frame") << json["geometry"].dump();
    rows.push_back(json["geometry"]["horizon_row"].get<double>());
  }
  EXPECT_NEAR(rows[0] - rows[1], shift, 0.02 * frame.rows);
}

// The bounds: at most --max-cameras cameras, and one not seen for --camera-idle is forgotten.
TEST(CameraBoundsTest, TheServerKeepsAtMostMaxCamerasAndForgetsIdleOnes) {
  REQUIRE_MODEL();
  const auto server = ServerProcess::Start(
      TestModel(), {"--workers", "1", "--max-cameras", "2", "--camera-idle", "2"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  httplib::Client http("127.0.0.1", server->http_port());
  http.set_read_timeout(120s);
  const std::string frame = testing::RoadPng();
  for (const char* camera : {"cam-a", "cam-b", "cam-c", "cam-d", "cam-e"}) {
    int status = 0;
    const nlohmann::json json =
        PostDetect(http, std::string("&camera_id=") + camera, frame, &status);
    ASSERT_EQ(status, 200) << json.dump();
    EXPECT_LE(MetricValue(server->Metrics(), "tod_cameras_tracked").value_or(-1), 2);
  }
  EXPECT_GE(MetricValue(server->Metrics(), "tod_cameras_tracked").value_or(0), 1);
  // Longer than the idle time: the next camera's arrival forgets every other one.
  std::this_thread::sleep_for(2500ms);
  int status = 0;
  PostDetect(http, "&camera_id=cam-f", frame, &status);
  ASSERT_EQ(status, 200);
  EXPECT_EQ(MetricValue(server->Metrics(), "tod_cameras_tracked").value_or(-1), 1)
      << server->Metrics();
}

}  // namespace
}  // namespace tod::server
