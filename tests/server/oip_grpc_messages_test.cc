// The Open Inference Protocol's gRPC messages: the image from either of its two places, every
// refusal naming its field, options as typed parameters, and the answer's raw output contents
// decoding back to the tensors.
#include "server/oip/oip_grpc_messages.h"

#include <gtest/gtest.h>

#include <cstring>

#include "server/oip/oip_model.h"

namespace tod::server::oip {
namespace {

using nlohmann::json;

std::string BinaryElement(const std::string& bytes) {
  return BinaryTensorData(std::vector<std::string>{bytes});
}

inference::ModelInferRequest RawRequest(const std::string& image) {
  inference::ModelInferRequest request;
  request.set_model_name("m");
  auto* input = request.add_inputs();
  input->set_name("image");
  input->set_datatype("BYTES");
  input->add_shape(1);
  request.add_raw_input_contents(BinaryElement(image));
  return request;
}

void ExpectRefused(const Result<InferRequest>& parsed, StatusCode code, const std::string& part) {
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.status().code(), code);
  EXPECT_NE(parsed.status().message().find(part), std::string::npos) << parsed.status().message();
}

TEST(OipGrpcMessages, ReadsTheImageFromRawInputContents) {
  const inference::ModelInferRequest request = RawRequest("frame bytes");
  const Result<InferRequest> parsed = FromModelInferRequest(request, {});
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->image(), "frame bytes");
  EXPECT_FALSE(parsed->id.has_value());
  EXPECT_TRUE(parsed->outputs.empty());
}

TEST(OipGrpcMessages, ReadsTheImageFromBytesContents) {
  inference::ModelInferRequest request = RawRequest("x");
  request.clear_raw_input_contents();
  request.mutable_inputs(0)->mutable_contents()->add_bytes_contents("typed frame");
  request.set_id("req-1");
  const Result<InferRequest> parsed = FromModelInferRequest(request, {});
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->image(), "typed frame");
  EXPECT_EQ(parsed->id, "req-1");
}

TEST(OipGrpcMessages, RefusesMalformedInputsNamingTheField) {
  const auto refused = [](auto change, StatusCode code, const std::string& part) {
    inference::ModelInferRequest request = RawRequest("frame");
    change(request);
    ExpectRefused(FromModelInferRequest(request, {.max_image_bytes = 100}), code, part);
  };
  const StatusCode bad = StatusCode::kInvalidArgument;
  refused([](auto& r) { r.clear_inputs(); }, bad, "one input");
  refused([](auto& r) { r.mutable_inputs(0)->set_name("img"); }, bad, "inputs[0].name");
  refused([](auto& r) { r.mutable_inputs(0)->set_datatype("UINT8"); }, bad, "datatype");
  refused([](auto& r) { r.mutable_inputs(0)->add_shape(2); }, bad, "shape must be [1]");
  refused([](auto& r) { r.mutable_inputs(0)->set_shape(0, 2); }, bad, "shape must be [1]");
  refused([](auto& r) { r.add_raw_input_contents("x"); }, bad, "raw_input_contents has 2");
  refused([](auto& r) { r.set_raw_input_contents(0, "frame"); }, bad, "declares");
  refused([](auto& r) { r.set_raw_input_contents(0, "abc"); }, bad, "4-byte length");
  refused([](auto& r) { r.mutable_inputs(0)->mutable_contents()->add_bytes_contents("x"); }, bad,
          "both contents and raw_input_contents");
  refused(
      [](auto& r) {
        r.clear_raw_input_contents();
        r.mutable_inputs(0)->mutable_contents()->add_fp32_contents(1);
      },
      bad, "contents.bytes_contents");
  refused([](auto& r) { r.set_raw_input_contents(0, BinaryElement(std::string(101, 'x'))); },
          StatusCode::kResourceExhausted, "over the limit of 100");
  refused(
      [](auto& r) {
        r.clear_raw_input_contents();
        r.mutable_inputs(0)->mutable_contents()->add_bytes_contents(std::string(101, 'x'));
      },
      StatusCode::kResourceExhausted, "over the limit of 100");
  refused(
      [](auto& r) {
        r.add_outputs()->set_name("obstacles");
        r.add_outputs()->set_name("obstacles");
      },
      bad, "a second time");
}

TEST(OipGrpcMessages, TypedParametersBecomeTheQueryOptions) {
  inference::ModelInferRequest request = RawRequest("frame");
  auto& parameters = *request.mutable_parameters();
  parameters["max_proposals"].set_int64_param(25);
  parameters["obstacle_threshold"].set_double_param(0.25);
  parameters["frame_id"].set_string_param("cam7-0001");
  parameters["map_format"].set_string_param("uint8");
  parameters["something_else"].set_bool_param(true);  // extensions are left alone
  const Result<InferRequest> parsed = FromModelInferRequest(request, {});
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->options.at("max_proposals"), "25");
  EXPECT_EQ(parsed->options.at("obstacle_threshold"), "0.25");
  EXPECT_EQ(parsed->options.at("frame_id"), "cam7-0001");
  EXPECT_EQ(parsed->options.count("something_else"), 0u);
  EXPECT_EQ(parsed->map_format, MapFormat::kUint8);

  InferenceRequest inference;
  std::string frame_id = "default";
  ASSERT_TRUE(ApplyOptions(*parsed, &inference, &frame_id).ok());
  EXPECT_EQ(frame_id, "cam7-0001");
  EXPECT_EQ(inference.options.max_proposals, 25);

  // Booleans are read as "true"/"false": calibrate takes one, a number option refuses it.
  parameters["calibrate"].set_bool_param(false);
  parameters["camera_id"].set_string_param("cam7");
  const Result<InferRequest> calibrated = FromModelInferRequest(request, {});
  ASSERT_TRUE(calibrated.ok());
  ASSERT_TRUE(ApplyOptions(*calibrated, &inference, &frame_id).ok());
  EXPECT_FALSE(inference.options.calibrate);
  EXPECT_EQ(inference.camera_id, "cam7");
  parameters["max_proposals"].set_bool_param(true);
  const Result<InferRequest> boolean = FromModelInferRequest(request, {});
  ASSERT_TRUE(boolean.ok());
  EXPECT_NE(ApplyOptions(*boolean, &inference, &frame_id).message().find("max_proposals"),
            std::string::npos);
  parameters["max_proposals"].clear_parameter_choice();  // no value at all
  ExpectRefused(FromModelInferRequest(request, {}), StatusCode::kInvalidArgument,
                "parameter max_proposals must be a number, a string or a boolean");
  parameters["max_proposals"].set_int64_param(-3);
  const Result<InferRequest> negative = FromModelInferRequest(request, {});
  ASSERT_TRUE(negative.ok());
  const Status range = ApplyOptions(*negative, &inference, &frame_id);
  EXPECT_EQ(range.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(range.message().find("query"), std::string::npos) << range.message();
  parameters["max_proposals"].set_int64_param(3);
  parameters["map_format"].set_string_param("jpeg");
  ExpectRefused(FromModelInferRequest(request, {}), StatusCode::kInvalidArgument, "map_format");
}

TEST(OipGrpcMessages, OutputsGoToRawContentsInBinaryForm) {
  OutputTensor boxes{"obstacles", {1, 2}, std::vector<float>{1.5f, -2.0f}};
  boxes.parameters = {{"columns", "a,b"}};
  const OutputTensor map{"probability_map", {1}, std::vector<std::string>{"png"}};
  const json head = {
      {"model_name", "m"},
      {"model_version", "3"},
      {"id", "r"},
      {"parameters", {{"frame_id", "f"}, {"width", 4}, {"degraded", false}, {"total_ms", 1.5}}}};
  const inference::ModelInferResponse response = ToModelInferResponse(head, {boxes, map});
  EXPECT_EQ(response.model_name(), "m");
  EXPECT_EQ(response.model_version(), "3");
  EXPECT_EQ(response.id(), "r");
  EXPECT_EQ(response.parameters().at("frame_id").string_param(), "f");
  EXPECT_EQ(response.parameters().at("width").int64_param(), 4);
  EXPECT_FALSE(response.parameters().at("degraded").bool_param());
  EXPECT_DOUBLE_EQ(response.parameters().at("total_ms").double_param(), 1.5);
  ASSERT_EQ(response.outputs_size(), 2);
  ASSERT_EQ(response.raw_output_contents_size(), 2);
  EXPECT_EQ(response.outputs(0).datatype(), "FP32");
  EXPECT_EQ(response.outputs(0).shape_size(), 2);
  EXPECT_EQ(response.outputs(0).parameters().at("columns").string_param(), "a,b");
  const std::string& floats = response.raw_output_contents(0);
  ASSERT_EQ(floats.size(), 8u);
  float first = 0;
  float second = 0;
  std::memcpy(&first, floats.data(), 4);  // little-endian, as this machine is
  std::memcpy(&second, floats.data() + 4, 4);
  EXPECT_EQ(first, 1.5f);
  EXPECT_EQ(second, -2.0f);
  EXPECT_EQ(response.outputs(1).datatype(), "BYTES");
  EXPECT_EQ(response.raw_output_contents(1), BinaryElement("png"));
}

TEST(OipGrpcMessages, MetadataMatchesTheRestForm) {
  ModelInfo info;
  info.name = "default";
  info.version = "7";
  const json rest = ModelMetadata(info);
  const inference::ModelMetadataResponse metadata = ToModelMetadataResponse(rest);
  EXPECT_EQ(metadata.name(), "default");
  ASSERT_EQ(metadata.versions_size(), 1);
  EXPECT_EQ(metadata.versions(0), "7");
  EXPECT_EQ(metadata.platform(), rest["platform"]);
  ASSERT_EQ(metadata.inputs_size(), 1);
  EXPECT_EQ(metadata.inputs(0).name(), "image");
  EXPECT_EQ(metadata.inputs(0).datatype(), "BYTES");
  ASSERT_EQ(metadata.outputs_size(), 3);
  EXPECT_EQ(metadata.outputs(0).name(), "obstacles");
  EXPECT_EQ(metadata.outputs(0).shape(0), -1);
  EXPECT_EQ(metadata.outputs(0).shape(1), 9);
  const inference::ServerMetadataResponse server = ToServerMetadataResponse(ServerMetadata());
  EXPECT_EQ(server.name(), "tod");
  ASSERT_EQ(server.extensions_size(), 1);
  EXPECT_EQ(server.extensions(0), "binary_tensor_data");
}

}  // namespace
}  // namespace tod::server::oip
