// The JSON form of the tod.v1 messages (proto/json/message_json.h), which the REST front end
// answers with (compact) and tod_client writes and prints (indented): its keys and bytes are an
// API, so they are pinned here on a sample detection, byte for byte as the server's and the
// client's own conversions printed them before they became this one. And the CLI's JSON of a
// detection (core DetectionToJson, other keys: `tod detect`'s format) carries the same numbers.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/pipeline/detection_output.h"
#include "proto/json/message_json.h"
#include "server/detect_response.h"
#include "tests/service/fake_detectors.h"

namespace tod::server {
namespace {

using proto::JsonLayout;
using proto::MessageToJson;

InferenceResult SampleResult() {
  InferenceResult result;
  auto model = std::make_shared<LoadedModel>();
  model->detector = std::make_shared<testing::GatedDetector>("v7");
  result.model = model;
  Detection& detection = result.detection;
  detection.width = 40;
  detection.height = 20;
  detection.obstacles.push_back({Box{1, 2, 3, 4}, 11, 0.75f, 0.5f, 1.25f, 0.625f});
  detection.proposals.push_back({Box{5, 6, 7, 8}, 1.5f, 1.0f, 0.25f});
  detection.probability = cv::Mat1f(20, 40, 0.f);
  detection.map_kind = MapKind::kCalibrated;
  detection.degraded_stages = {"regression"};
  detection.horizon = {HorizonSource::kCamera, 9.5, 8.0, 10.0, 20, 1.5, ""};
  detection.road_region = Box{0, 10, 40, 10};
  result.map_png = "PNG";
  result.timings = {{"queue", 1.5}, {"decode", 2.0}};
  result.total_ms = 9.5;
  return result;
}

tod::v1::DetectResponse SampleResponse() {
  tod::v1::DetectResponse response;
  FillDetectResponse(SampleResult(), "frame-3", &response);
  return response;
}

TEST(ProtoJsonTest, CompactDetectResponseBytes) {
  EXPECT_EQ(
      MessageToJson(SampleResponse()),
      R"({"frame_id":"frame-3","model_version":"v7","width":40,"height":20,)"
      R"("obstacles":[{"box":{"x":1,"y":2,"w":3,"h":4},"area":11,"peak_probability":0.75,)"
      R"("mean_probability":0.5,"score":0.625,"evidence":1.25}],)"
      R"("proposals":[{"box":{"x":5,"y":6,"w":7,"h":8},"fused":1.5,"ordr":1,"obdr":0.25}],)"
      R"("probability_map":{"width":40,"height":20,"png":"UE5H","kind":"MAP_KIND_CALIBRATED"},)"
      R"("timings":[{"stage":"queue","ms":1.5},{"stage":"decode","ms":2}],"total_ms":9.5,)"
      R"("degraded":true,"degraded_stages":["regression"],)"
      R"("geometry":{"source":"camera","camera_frames":20,"shift_rows":1.5,)"
      R"("road_region":{"x":0,"y":10,"w":40,"h":10},"fallback":"",)"
      R"("horizon_row":9.5,"bundle_horizon_row":8,"frame_horizon_row":10}})");
}

TEST(ProtoJsonTest, DefaultsArePrintedAndAnUnsetMapIsLeftOut) {
  EXPECT_EQ(MessageToJson(tod::v1::DetectResponse()),
            R"({"frame_id":"","model_version":"","width":0,"height":0,"obstacles":[],)"
            R"("proposals":[],"timings":[],"total_ms":0,"degraded":false,"degraded_stages":[]})");
}

// What tod_client writes to <stem>.json (before its own trailing newline) and prints.
constexpr char kIndentedSample[] = R"({
 "frame_id": "frame-3",
 "model_version": "v7",
 "width": 40,
 "height": 20,
 "obstacles": [
  {
   "box": {
    "x": 1,
    "y": 2,
    "w": 3,
    "h": 4
   },
   "area": 11,
   "peak_probability": 0.75,
   "mean_probability": 0.5,
   "score": 0.625,
   "evidence": 1.25
  }
 ],
 "proposals": [
  {
   "box": {
    "x": 5,
    "y": 6,
    "w": 7,
    "h": 8
   },
   "fused": 1.5,
   "ordr": 1,
   "obdr": 0.25
  }
 ],
 "probability_map": {
  "width": 40,
  "height": 20,
  "png": "UE5H",
  "kind": "MAP_KIND_CALIBRATED"
 },
 "timings": [
  {
   "stage": "queue",
   "ms": 1.5
  },
  {
   "stage": "decode",
   "ms": 2
  }
 ],
 "total_ms": 9.5,
 "degraded": true,
 "degraded_stages": [
  "regression"
 ],
 "geometry": {
  "source": "camera",
  "camera_frames": 20,
  "shift_rows": 1.5,
  "road_region": {
   "x": 0,
   "y": 10,
   "w": 40,
   "h": 10
  },
  "fallback": "",
  "horizon_row": 9.5,
  "bundle_horizon_row": 8,
  "frame_horizon_row": 10
 }
}
)";

TEST(ProtoJsonTest, IndentedDetectResponseBytes) {
  EXPECT_EQ(MessageToJson(SampleResponse(), JsonLayout::kIndented), kIndentedSample);
  EXPECT_EQ(MessageToJson(tod::v1::DetectResponse(), JsonLayout::kIndented),
            "{\n \"frame_id\": \"\",\n \"model_version\": \"\",\n \"width\": 0,\n \"height\": 0,\n"
            " \"obstacles\": [],\n \"proposals\": [],\n \"timings\": [],\n \"total_ms\": 0,\n"
            " \"degraded\": false,\n \"degraded_stages\": []\n}\n");
}

TEST(ProtoJsonTest, ModelInfoBytes) {
  LoadedModel model;
  model.detector = std::make_shared<testing::GatedDetector>("v7");
  model.generation = 2;
  model.loaded_at = "2026-01-02T03:04:05Z";
  tod::v1::ModelInfo info;
  FillModelInfo(model, &info);
  EXPECT_EQ(MessageToJson(info),
            R"({"name":"gated","version":"v7","format_version":0,"created":"","trained_on":"",)"
            R"("edge_source":"","manifest_json":"null","model_dir":"gated","generation":2,)"
            R"("loaded_at":"2026-01-02T03:04:05Z"})");
  EXPECT_EQ(MessageToJson(info, JsonLayout::kIndented),
            "{\n \"name\": \"gated\",\n \"version\": \"v7\",\n \"format_version\": 0,\n"
            " \"created\": \"\",\n \"trained_on\": \"\",\n \"edge_source\": \"\",\n"
            " \"manifest_json\": \"null\",\n \"model_dir\": \"gated\",\n \"generation\": 2,\n"
            " \"loaded_at\": \"2026-01-02T03:04:05Z\"\n}\n");
}

std::vector<std::string> Keys(const nlohmann::json& object) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : object.items()) keys.push_back(key);
  return keys;
}

using KeyList = std::vector<std::string>;

TEST(ProtoJsonTest, KeysOfEveryLevel) {
  const nlohmann::json json = nlohmann::json::parse(MessageToJson(SampleResponse()));
  EXPECT_EQ(Keys(json), (KeyList{"degraded", "degraded_stages", "frame_id", "geometry", "height",
                                 "model_version", "obstacles", "probability_map", "proposals",
                                 "timings", "total_ms", "width"}));
  // The optional rows (proto3 `optional`) are printed after the other fields, when set.
  EXPECT_EQ(Keys(json["geometry"]),
            (KeyList{"bundle_horizon_row", "camera_frames", "fallback", "frame_horizon_row",
                     "horizon_row", "road_region", "shift_rows", "source"}));
  EXPECT_EQ(Keys(json["obstacles"][0]),
            (KeyList{"area", "box", "evidence", "mean_probability", "peak_probability", "score"}));
  EXPECT_EQ(Keys(json["obstacles"][0]["box"]), (KeyList{"h", "w", "x", "y"}));
  EXPECT_EQ(Keys(json["proposals"][0]), (KeyList{"box", "fused", "obdr", "ordr"}));
  EXPECT_EQ(Keys(json["probability_map"]), (KeyList{"height", "kind", "png", "width"}));
  EXPECT_EQ(Keys(json["timings"][0]), (KeyList{"ms", "stage"}));
}

// The two documents differ in layout by design (`tod detect` flattens the boxes and names the
// scores peak/mean/score; the API nests them), and in timings (the CLI sums the pipeline's
// stages, the API counts from admission); every number of the detection itself agrees.
TEST(ProtoJsonTest, AgreesWithTheCliJsonOnADetection) {
  const InferenceResult result = SampleResult();
  const nlohmann::json cli = DetectionToJson(result.detection, "frame-3.png");
  const nlohmann::json api = nlohmann::json::parse(MessageToJson(SampleResponse()));
  EXPECT_EQ(cli["width"], api["width"]);
  EXPECT_EQ(cli["height"], api["height"]);
  ASSERT_EQ(cli["obstacles"].size(), api["obstacles"].size());
  for (size_t i = 0; i < cli["obstacles"].size(); ++i) {
    const nlohmann::json& c = cli["obstacles"][i];
    const nlohmann::json& a = api["obstacles"][i];
    for (const char* key : {"x", "y", "w", "h"}) EXPECT_EQ(c[key], a["box"][key]) << key;
    EXPECT_EQ(c["area"], a["area"]);
    EXPECT_EQ(c["peak"], a["peak_probability"]);
    EXPECT_EQ(c["mean"], a["mean_probability"]);
    EXPECT_EQ(c["score"], a["score"]);
    EXPECT_EQ(c["evidence"], a["evidence"]);
  }
  ASSERT_EQ(cli["proposals"].size(), api["proposals"].size());
  for (size_t i = 0; i < cli["proposals"].size(); ++i) {
    const nlohmann::json& c = cli["proposals"][i];
    const nlohmann::json& a = api["proposals"][i];
    for (const char* key : {"x", "y", "w", "h"}) EXPECT_EQ(c[key], a["box"][key]) << key;
    EXPECT_EQ(c["score"], a["fused"]);
    EXPECT_EQ(c["ordr"], a["ordr"]);
    EXPECT_EQ(c["obdr"], a["obdr"]);
  }
  EXPECT_EQ(cli["map_kind"], "calibrated");
  EXPECT_EQ(api["probability_map"]["kind"], "MAP_KIND_CALIBRATED");
  EXPECT_EQ(cli["degraded"], api["degraded"]);
  EXPECT_EQ(cli["degraded_stages"], api["degraded_stages"]);
  // The geometry has the same keys and numbers in both (the CLI leaves an empty fallback out).
  for (const char* key : {"source", "horizon_row", "bundle_horizon_row", "frame_horizon_row",
                          "camera_frames", "shift_rows", "road_region"}) {
    EXPECT_EQ(cli["geometry"][key], api["geometry"][key]) << key;
  }
}

}  // namespace
}  // namespace tod::server
