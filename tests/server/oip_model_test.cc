// The detector as an Open Inference Protocol model: metadata, the output columns of a detection
// (against the values of the detection itself), the map's two formats and output selection.
#include "server/oip/oip_model.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tod::server::oip {
namespace {

using nlohmann::json;

InferenceResult ExampleResult() {
  InferenceResult result;
  Detection& detection = result.detection;
  detection.width = 4;
  detection.height = 2;
  DetectedObstacle obstacle;
  obstacle.box = Box{1, 2, 3, 4};
  obstacle.area = 12;
  obstacle.peak_probability = 0.9f;
  obstacle.mean_probability = 0.6f;
  obstacle.evidence = 0.7f;
  obstacle.score = 0.8f;
  detection.obstacles = {obstacle};
  detection.proposals = {{Box{5, 6, 7, 8}, 0.5f, 0.4f, 0.1f}, {Box{0, 0, 2, 2}, 0.3f, 0.2f, 0.1f}};
  detection.probability = cv::Mat1f(2, 4, 0.5f);
  detection.probability(1, 3) = 1.5f;  // saturates
  detection.probability(0, 0) = -1;    // saturates
  detection.degraded_stages = {"proposals", "regression"};
  result.map_png = "png bytes";
  result.total_ms = 12.5;
  return result;
}

const std::vector<float>& Floats(const OutputTensor& tensor) {
  return std::get<std::vector<float>>(tensor.data);
}

TEST(OipModelTest, MetadataDescribesOneBytesInputAndThreeOutputs) {
  ModelInfo info;
  info.name = "tiny";
  info.version = "tod-2026-01-01-seed1";
  const json metadata = ModelMetadata(info);
  EXPECT_EQ(metadata["name"], "tiny");
  EXPECT_EQ(metadata["versions"], json({"tod-2026-01-01-seed1"}));
  EXPECT_EQ(metadata["inputs"],
            json::parse(R"([{"name":"image","datatype":"BYTES","shape":[1]}])"));
  ASSERT_EQ(metadata["outputs"].size(), 3u);
  EXPECT_EQ(metadata["outputs"][0]["name"], "obstacles");
  EXPECT_EQ(metadata["outputs"][0]["shape"], json({-1, 9}));
  EXPECT_EQ(metadata["outputs"][0]["parameters"]["columns"],
            "x,y,w,h,score,peak_probability,mean_probability,evidence,area");
  EXPECT_EQ(metadata["outputs"][1]["shape"], json({-1, 7}));
  EXPECT_EQ(metadata["outputs"][1]["parameters"]["columns"], "x,y,w,h,fused,ordr,obdr");
  EXPECT_EQ(metadata["outputs"][2]["datatype"], "BYTES");
  info.version.clear();
  EXPECT_EQ(ModelMetadata(info)["versions"], json({"1"}));  // a manifest without a version
  EXPECT_EQ(ServerMetadata()["name"], "tod");
  EXPECT_EQ(ServerMetadata()["extensions"], json({"binary_tensor_data"}));
}

TEST(OipModelTest, AllOutputsByDefaultInDetectionOrderWithDocumentedColumns) {
  InferRequest request;
  const Result<std::vector<OutputTensor>> outputs = BuildOutputs(request, ExampleResult());
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();
  ASSERT_EQ(outputs->size(), 3u);
  EXPECT_EQ((*outputs)[0].name, "obstacles");
  EXPECT_EQ((*outputs)[0].shape, (std::vector<int64_t>{1, 9}));
  EXPECT_EQ(Floats((*outputs)[0]), (std::vector<float>{1, 2, 3, 4, 0.8f, 0.9f, 0.6f, 0.7f, 12}));
  EXPECT_EQ((*outputs)[1].name, "proposals");
  EXPECT_EQ((*outputs)[1].shape, (std::vector<int64_t>{2, 7}));
  EXPECT_EQ(Floats((*outputs)[1]), (std::vector<float>{5, 6, 7, 8, 0.5f, 0.4f, 0.1f,  //
                                                       0, 0, 2, 2, 0.3f, 0.2f, 0.1f}));
  EXPECT_EQ((*outputs)[2].name, "probability_map");
  EXPECT_EQ(std::get<std::vector<std::string>>((*outputs)[2].data),
            std::vector<std::string>{"png bytes"});
  for (const OutputTensor& output : *outputs) EXPECT_FALSE(output.binary);

  request.binary_data_output = true;
  for (const OutputTensor& output : *BuildOutputs(request, ExampleResult())) {
    EXPECT_TRUE(output.binary) << output.name;
  }
}

TEST(OipModelTest, SelectedOutputsInRequestOrderAndTheMapAsPixels) {
  InferRequest request;
  request.map_format = MapFormat::kUint8;
  request.outputs = {{"probability_map", true}, {"proposals", false}};
  ASSERT_TRUE(CheckOutputs(request).ok());
  EXPECT_TRUE(WantsMap(request));
  const Result<std::vector<OutputTensor>> outputs = BuildOutputs(request, ExampleResult());
  ASSERT_TRUE(outputs.ok()) << outputs.status().message();
  ASSERT_EQ(outputs->size(), 2u);
  EXPECT_EQ((*outputs)[0].shape, (std::vector<int64_t>{2, 4}));
  EXPECT_TRUE((*outputs)[0].binary);
  // round(255 * P), saturated: as the PNG holds it.
  EXPECT_EQ(std::get<std::vector<uint8_t>>((*outputs)[0].data),
            (std::vector<uint8_t>{0, 128, 128, 128, 128, 128, 128, 255}));
  EXPECT_EQ((*outputs)[1].name, "proposals");

  request.outputs = {{"obstacles", false}};
  EXPECT_FALSE(WantsMap(request));
  request.outputs = {{"obstacles", false}, {"boxes", false}};
  const Status unknown = CheckOutputs(request);
  EXPECT_EQ(unknown.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(unknown.message().find("no output 'boxes'"), std::string::npos);

  // The map asked for but not made: an internal error, not an empty tensor.
  InferenceResult no_map = ExampleResult();
  no_map.map_png.clear();
  request.map_format = MapFormat::kPng;
  request.outputs = {{"probability_map", false}};
  EXPECT_EQ(BuildOutputs(request, no_map).status().code(), StatusCode::kInternal);
}

TEST(OipModelTest, TheHeadEchoesTheIdAndCarriesTheFrameFacts) {
  InferRequest request;
  request.id = "r1";
  const json head = ResponseHead(request, ExampleResult(), "cam0");
  EXPECT_EQ(head["id"], "r1");
  EXPECT_EQ(head["parameters"]["frame_id"], "cam0");
  EXPECT_EQ(head["parameters"]["width"], 4);
  EXPECT_EQ(head["parameters"]["height"], 2);
  EXPECT_EQ(head["parameters"]["degraded"], true);
  EXPECT_EQ(head["parameters"]["degraded_stages"], "proposals,regression");
  EXPECT_EQ(head["parameters"]["map_kind"], "normalized");
  EXPECT_FALSE(ResponseHead(InferRequest(), ExampleResult(), "f").contains("id"));
}

}  // namespace
}  // namespace tod::server::oip
