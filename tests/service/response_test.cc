// Engine results -> tod.v1 messages -> JSON, and the status code table.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "proto/json/message_json.h"
#include "server/detect_response.h"
#include "server/status_mapping.h"
#include "tests/service/fake_detectors.h"

namespace tod::server {
namespace {

TEST(DetectResponseTest, CarriesEveryFieldIntoJson) {
  InferenceResult result;
  auto model = std::make_shared<LoadedModel>();
  model->detector = std::make_shared<testing::GatedDetector>("v7");
  result.model = model;
  result.detection.width = 40;
  result.detection.height = 20;
  result.detection.obstacles.push_back({Box{1, 2, 3, 4}, 11, 0.75f, 0.5f});
  result.detection.proposals.push_back({Box{5, 6, 7, 8}, 1.5f, 1.0f, 0.25f});
  result.detection.probability = cv::Mat1f(20, 40, 0.f);
  result.map_png = "PNG";
  result.timings = {{"queue", 1.5}, {"decode", 2.0}};
  result.total_ms = 9.5;

  tod::v1::DetectResponse response;
  FillDetectResponse(result, "frame-3", &response);
  const nlohmann::json json = nlohmann::json::parse(proto::MessageToJson(response));
  EXPECT_EQ(json["frame_id"], "frame-3");
  EXPECT_EQ(json["model_version"], "v7");
  EXPECT_EQ(json["width"], 40);
  EXPECT_EQ(json["height"], 20);
  EXPECT_EQ(json["obstacles"][0]["box"]["x"], 1);
  EXPECT_EQ(json["obstacles"][0]["box"]["h"], 4);
  EXPECT_EQ(json["obstacles"][0]["area"], 11);
  EXPECT_DOUBLE_EQ(json["obstacles"][0]["peak_probability"].get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(json["proposals"][0]["fused"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(json["proposals"][0]["obdr"].get<double>(), 0.25);
  EXPECT_EQ(json["probability_map"]["width"], 40);
  EXPECT_EQ(json["probability_map"]["png"], "UE5H");  // base64("PNG")
  EXPECT_EQ(json["timings"][1]["stage"], "decode");
  EXPECT_DOUBLE_EQ(json["total_ms"].get<double>(), 9.5);
}

TEST(DetectResponseTest, OptionsDefaultsAndOverrides) {
  tod::v1::DetectOptions options;
  RequestOptions defaults = OptionsFromProto(options);
  EXPECT_EQ(defaults.detect.max_proposals, DetectOptions{}.max_proposals);
  EXPECT_FLOAT_EQ(defaults.detect.obstacle_threshold, DetectOptions{}.obstacle_threshold);
  EXPECT_TRUE(defaults.encode_map_png);  // unspecified -> PNG
  options.set_max_proposals(0);          // an explicit 0 is kept, not taken as "unset"
  options.set_obstacle_threshold(0.f);
  options.set_map_format(tod::v1::MAP_FORMAT_NONE);
  const RequestOptions set = OptionsFromProto(options);
  EXPECT_EQ(set.detect.max_proposals, 0);
  EXPECT_FLOAT_EQ(set.detect.obstacle_threshold, 0.f);
  EXPECT_FALSE(set.encode_map_png);
}

TEST(StatusMappingTest, HttpCodesFollowTheIssue) {
  EXPECT_EQ(HttpStatusFor(Status::Ok(), Rejection::kNone), 200);
  EXPECT_EQ(HttpStatusFor(Status::InvalidArgument("x"), Rejection::kBadImage), 400);
  EXPECT_EQ(HttpStatusFor(Status::ResourceExhausted("x"), Rejection::kTooLarge), 413);
  EXPECT_EQ(HttpStatusFor(Status::ResourceExhausted("x"), Rejection::kQueueFull), 503);
  EXPECT_EQ(HttpStatusFor(Status::Unavailable("x"), Rejection::kNotReady), 503);
  EXPECT_EQ(HttpStatusFor(Status::DeadlineExceeded("x"), Rejection::kDeadline), 504);
  EXPECT_EQ(HttpStatusFor(Status::Internal("x"), Rejection::kInternal), 500);
  EXPECT_EQ(ToGrpcStatus(Status::ResourceExhausted("full")).error_code(),
            grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(ToGrpcStatus(Status::ResourceExhausted("full")).error_message(), "full");
  EXPECT_EQ(GrpcCodeName(grpc::StatusCode::DEADLINE_EXCEEDED), "DEADLINE_EXCEEDED");
}

}  // namespace
}  // namespace tod::server
