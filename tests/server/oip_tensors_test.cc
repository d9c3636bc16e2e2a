// The Open Inference Protocol's bodies without a network: infer requests in JSON and with the
// binary tensor data extension, every refusal of a malformed, oversized or inconsistent body,
// the encoding of answers, base64 and the model paths.
#include "server/oip/oip_tensors.h"

#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>
#include <string>

#include "server/oip/oip_base64.h"
#include "server/oip/oip_path.h"

namespace tod::server::oip {
namespace {

using nlohmann::json;

// Bytes no JSON string could carry raw: NUL, invalid UTF-8, quotes.
const std::string kImage = std::string("\x89PNG\r\n\x1a\n\0\xff\xfe\"\\", 14) + "rest of a frame";

json ImageInput(const std::string& image = kImage) {
  return {
      {"name", "image"}, {"datatype", "BYTES"}, {"shape", {1}}, {"data", {Base64Encode(image)}}};
}

json JsonRequest() { return {{"inputs", {ImageInput()}}}; }

std::string LittleEndian32(uint32_t value) {
  std::string out(4, '\0');
  for (int i = 0; i < 4; ++i) out[i] = static_cast<char>(value >> (8 * i));
  return out;
}

// A binary-extension body: the JSON header, then the image as one BYTES element.
struct BinaryBody {
  std::string body;
  std::string header_length;
};
BinaryBody BinaryRequest(const std::string& image = kImage, json header = json()) {
  const std::string element = LittleEndian32(static_cast<uint32_t>(image.size())) + image;
  if (header.is_null()) {
    header = {{"inputs",
               {{{"name", "image"},
                 {"datatype", "BYTES"},
                 {"shape", {1}},
                 {"parameters", {{"binary_data_size", element.size()}}}}}}};
  }
  const std::string text = header.dump();
  return {text + element, std::to_string(text.size())};
}

Result<InferRequest> Parse(const std::string& body,
                           std::optional<std::string_view> header_length = std::nullopt,
                           const BodyLimits& limits = {}) {
  return ParseInferRequest(body, header_length, limits);
}

// The refusal of `body`: its code and that its message names `part`.
void ExpectRefused(const Result<InferRequest>& result, StatusCode code, const std::string& part) {
  ASSERT_FALSE(result.ok()) << "accepted; expected a refusal naming " << part;
  EXPECT_EQ(result.status().code(), code) << result.status().message();
  EXPECT_NE(result.status().message().find(part), std::string::npos) << result.status().message();
}

TEST(OipTensorsTest, AJsonRequestCarriesTheImageAsBase64AndItsOptionsAsQueryStrings) {
  json request = JsonRequest();
  request["id"] = "req-7";
  request["parameters"] = {{"max_proposals", 5},          {"obstacle_threshold", 0.25},
                           {"frame_id", "cam0-12"},       {"map_kind", "calibrated"},
                           {"map_format", "uint8"},       {"timeout_ms", 2000},
                           {"some_other_extension", true}};
  request["outputs"] = {{{"name", "obstacles"}},
                        {{"name", "probability_map"}, {"parameters", {{"binary_data", true}}}}};
  const Result<InferRequest> parsed = Parse(request.dump());
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->image(), kImage);
  EXPECT_FALSE(parsed->binary_image);
  EXPECT_EQ(parsed->id, "req-7");
  EXPECT_EQ(parsed->options.at("max_proposals"), "5");
  EXPECT_EQ(parsed->options.at("obstacle_threshold"), "0.25");
  EXPECT_EQ(parsed->options.at("frame_id"), "cam0-12");
  EXPECT_EQ(parsed->options.at("map_kind"), "calibrated");
  EXPECT_EQ(parsed->options.at("timeout_ms"), "2000");
  EXPECT_FALSE(parsed->options.contains("map_format"));  // not a detection option
  EXPECT_FALSE(parsed->options.contains("some_other_extension"));
  EXPECT_EQ(parsed->map_format, MapFormat::kUint8);
  ASSERT_EQ(parsed->outputs.size(), 2u);
  EXPECT_EQ(parsed->outputs[0].name, "obstacles");
  EXPECT_FALSE(parsed->outputs[0].binary);
  EXPECT_EQ(parsed->outputs[1].name, "probability_map");
  EXPECT_TRUE(parsed->outputs[1].binary);
}

TEST(OipTensorsTest, DataMayBeNestedAsItsShapeAndBinaryOutputIsTheRequestsDefault) {
  json request = {{"inputs",
                   {{{"name", "image"},
                     {"datatype", "BYTES"},
                     {"shape", {1, 1}},
                     {"data", {{Base64Encode(kImage)}}}}}},
                  {"parameters", {{"binary_data_output", true}}},
                  {"outputs",
                   {{{"name", "proposals"}},
                    {{"name", "obstacles"}, {"parameters", {{"binary_data", false}}}}}}};
  const Result<InferRequest> parsed = Parse(request.dump());
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  EXPECT_EQ(parsed->image(), kImage);
  EXPECT_TRUE(parsed->binary_data_output);
  EXPECT_TRUE(parsed->outputs[0].binary);
  EXPECT_FALSE(parsed->outputs[1].binary);
  EXPECT_EQ(parsed->map_format, MapFormat::kPng);
}

TEST(OipTensorsTest, TheBinaryExtensionViewsTheImageInTheBodyAfterItsLength) {
  const BinaryBody request = BinaryRequest();
  const Result<InferRequest> parsed = Parse(request.body, request.header_length);
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_TRUE(parsed->binary_image);
  EXPECT_EQ(parsed->image(), kImage);
  // A view, not a copy: it points into the body.
  EXPECT_EQ(parsed->image().data(), request.body.data() + request.body.size() - kImage.size());
  // The header alone (no binary part) is a plain JSON request.
  const std::string json_only = JsonRequest().dump();
  const Result<InferRequest> whole =
      Parse(json_only, std::to_string(json_only.size()) + " ");  // OWS around the value is fine
  ASSERT_TRUE(whole.ok()) << whole.status().message();
  EXPECT_EQ(whole->image(), kImage);
}

TEST(OipTensorsTest, BadFramingHeadersAreRefused) {
  const BinaryBody request = BinaryRequest();
  const StatusCode bad = StatusCode::kInvalidArgument;
  ExpectRefused(Parse(request.body, "abc"), bad, "Inference-Header-Content-Length");
  ExpectRefused(Parse(request.body, "-5"), bad, "not a byte count");
  ExpectRefused(Parse(request.body, "+5"), bad, "not a byte count");
  ExpectRefused(Parse(request.body, "12 34"), bad, "not a byte count");
  ExpectRefused(Parse(request.body, ""), bad, "not a byte count");
  ExpectRefused(Parse(request.body, "99999999999999999999999"), bad, "not a byte count");
  ExpectRefused(Parse(request.body, "0"), bad, "not within the body");
  ExpectRefused(Parse(request.body, std::to_string(request.body.size() + 1)), bad,
                "not within the body");
  // A length that cuts the JSON short makes it malformed.
  ExpectRefused(Parse(request.body, std::to_string(std::stoul(request.header_length) - 1)), bad,
                "malformed");
  // One that reaches into the binary data makes it malformed too (bytes after the JSON).
  ExpectRefused(Parse(request.body, std::to_string(std::stoul(request.header_length) + 2)), bad,
                "malformed");
}

TEST(OipTensorsTest, BinarySizesMustAddUpExactly) {
  const StatusCode bad = StatusCode::kInvalidArgument;
  // binary_data_size says one byte more than follows.
  const std::string element = LittleEndian32(kImage.size()) + kImage;
  json header = {{"inputs",
                  {{{"name", "image"},
                    {"datatype", "BYTES"},
                    {"shape", {1}},
                    {"parameters", {{"binary_data_size", element.size() + 1}}}}}}};
  BinaryBody request = BinaryRequest(kImage, header);
  ExpectRefused(Parse(request.body, request.header_length), bad, "binary_data_size is");
  // Binary bytes nobody claims.
  const std::string text = JsonRequest().dump();
  ExpectRefused(Parse(text + "tail", std::to_string(text.size())), bad, "no input claims them");
  // binary_data_size without the framing header.
  request = BinaryRequest();
  ExpectRefused(Parse(request.body), bad, "malformed");  // the binary tail is not JSON
  header = {{"inputs",
             {{{"name", "image"},
               {"datatype", "BYTES"},
               {"shape", {1}},
               {"parameters", {{"binary_data_size", 10}}}}}}};
  ExpectRefused(Parse(header.dump()), bad, "needs the Inference-Header-Content-Length");
  // Both JSON data and binary data.
  header["inputs"][0]["data"] = {Base64Encode(kImage)};
  header["inputs"][0]["parameters"]["binary_data_size"] = element.size();
  request = BinaryRequest(kImage, header);
  ExpectRefused(Parse(request.body, request.header_length), bad, "both data and");
  // A negative or fractional size.
  header["inputs"][0].erase("data");
  header["inputs"][0]["parameters"]["binary_data_size"] = -4;
  request = BinaryRequest(kImage, header);
  ExpectRefused(Parse(request.body, request.header_length), bad, "non-negative integer");
}

TEST(OipTensorsTest, TheBytesElementsLengthPrefixMustMatch) {
  const StatusCode bad = StatusCode::kInvalidArgument;
  const auto with_element = [](const std::string& element) {
    const json header = {{"inputs",
                          {{{"name", "image"},
                            {"datatype", "BYTES"},
                            {"shape", {1}},
                            {"parameters", {{"binary_data_size", element.size()}}}}}}};
    const std::string text = header.dump();
    return BinaryBody{text + element, std::to_string(text.size())};
  };
  BinaryBody request = with_element("abc");
  ExpectRefused(Parse(request.body, request.header_length), bad, "4-byte length");
  request = with_element(LittleEndian32(kImage.size() + 1) + kImage);
  ExpectRefused(Parse(request.body, request.header_length), bad, "declares");
  request = with_element(LittleEndian32(0xffffffffu) + kImage);
  ExpectRefused(Parse(request.body, request.header_length), bad, "declares");
  // Raw image bytes without the prefix.
  request = with_element(kImage);
  ExpectRefused(Parse(request.body, request.header_length), bad, "declares");
  // Over the image limit, refused before anything is copied.
  request = BinaryRequest(std::string(2000, 'x'));
  BodyLimits limits;
  limits.max_image_bytes = 1000;
  ExpectRefused(Parse(request.body, request.header_length, limits), StatusCode::kResourceExhausted,
                "over the limit of 1000");
}

TEST(OipTensorsTest, MalformedAndOversizedJsonIsRefusedBeforeItBecomesADocument) {
  const StatusCode bad = StatusCode::kInvalidArgument;
  ExpectRefused(Parse(""), bad, "empty");
  ExpectRefused(Parse("{\"inputs\": ["), bad, "malformed");
  ExpectRefused(Parse("{\"inputs\": []} trailing"), bad, "malformed");
  ExpectRefused(Parse("[1, 2]"), bad, "must be an object");
  ExpectRefused(Parse("\"text\""), bad, "must be an object");
  ExpectRefused(Parse(std::string(100, '[') + std::string(100, ']')), bad, "nests deeper than 8");
  // Depth 9 is refused at its opening bracket, however long the rest is.
  ExpectRefused(Parse(std::string(9, '[') + std::string(1'000'000, ' ')), bad, "nests deeper");
  std::string many = "{\"inputs\": [], \"x\": [";
  for (int i = 0; i < 100'000; ++i) many += "1,";
  many += "1]}";
  ExpectRefused(Parse(many), StatusCode::kResourceExhausted, "more than 512 values");
}

TEST(OipTensorsTest, InputsMustBeTheOneBytesImage) {
  const StatusCode bad = StatusCode::kInvalidArgument;
  json request = {{"id", 5}, {"inputs", {ImageInput()}}};
  ExpectRefused(Parse(request.dump()), bad, "\"id\" must be a string");
  ExpectRefused(Parse(json{{"parameters", 1}, {"inputs", {ImageInput()}}}.dump()), bad,
                "request.parameters must be an object");
  ExpectRefused(Parse(R"({"outputs": []})"), bad, "no \"inputs\" array");
  ExpectRefused(Parse(R"({"inputs": {}})"), bad, "no \"inputs\" array");
  ExpectRefused(Parse(R"({"inputs": []})"), bad, "the request has 0");
  ExpectRefused(Parse(json{{"inputs", {ImageInput(), ImageInput()}}}.dump()), bad,
                "the request has 2");
  ExpectRefused(Parse(R"({"inputs": [7]})"), bad, "inputs[0] must be an object");

  const auto with = [](const char* key, json value) {
    json request = JsonRequest();
    request["inputs"][0][key] = std::move(value);
    return request.dump();
  };
  ExpectRefused(Parse(with("name", "frame")), bad, "inputs[0].name");
  ExpectRefused(Parse(with("datatype", "UINT8")), bad, "inputs[0].datatype");
  ExpectRefused(Parse(with("shape", {2})), bad, "shape must be [1]");
  ExpectRefused(Parse(with("shape", {1, 0})), bad, "shape must be [1]");
  ExpectRefused(Parse(with("shape", json::array())), bad, "1 to 4 integers");
  ExpectRefused(Parse(with("shape", {1, 1, 1, 1, 1})), bad, "1 to 4 integers");
  ExpectRefused(Parse(with("shape", {-1})), bad, "not an integer in 0..2147483647");
  ExpectRefused(Parse(with("shape", {1.5})), bad, "not an integer");
  ExpectRefused(Parse(with("shape", {"1"})), bad, "not an integer");
  // A product far over 2^64 is refused, not overflowed into a small number.
  ExpectRefused(Parse(with("shape", {2147483647, 2147483647, 2147483647, 2147483647})), bad,
                "shape must be [1]");
  ExpectRefused(Parse(with("shape", {4294967297})), bad, "not an integer");
  ExpectRefused(Parse(with("data", json::array())), bad, "exactly one element");
  ExpectRefused(Parse(with("data", {"a", "b"})), bad, "exactly one element");
  ExpectRefused(Parse(with("data", json::parse(R"([[[[["QQ=="]]]]])"))), bad,
                "exactly one element");
  ExpectRefused(Parse(with("data", {42})), bad, "base64 string");
  ExpectRefused(Parse(with("data", {"not base64!"})), bad, "invalid character");
  ExpectRefused(Parse(with("data", {"QQ="})), bad, "impossible length");
  ExpectRefused(Parse(with("parameters", "x")), bad, "inputs[0].parameters must be an object");
  json no_data = JsonRequest();
  no_data["inputs"][0].erase("data");
  ExpectRefused(Parse(no_data.dump()), bad, "neither data nor binary data");

  BodyLimits limits;
  limits.max_image_bytes = 10;
  ExpectRefused(Parse(JsonRequest().dump(), std::nullopt, limits), StatusCode::kResourceExhausted,
                "decodes to 29 bytes, over the limit of 10");
}

TEST(OipTensorsTest, ParametersAndOutputsAreTypeChecked) {
  const StatusCode bad = StatusCode::kInvalidArgument;
  const auto with_parameters = [](json parameters) {
    json request = JsonRequest();
    request["parameters"] = std::move(parameters);
    return request.dump();
  };
  ExpectRefused(Parse(with_parameters({{"max_proposals", {{"a", 1}}}})), bad,
                "max_proposals must be a number, a string or a boolean");
  ExpectRefused(Parse(with_parameters({{"frame_id", {1, 2}}})), bad, "frame_id must be");
  ExpectRefused(Parse(with_parameters({{"map_format", "jpeg"}})), bad, "map_format");
  ExpectRefused(Parse(with_parameters({{"binary_data_output", "yes"}})), bad,
                "binary_data_output must be true or false");

  const auto with_outputs = [](json outputs) {
    json request = JsonRequest();
    request["outputs"] = std::move(outputs);
    return request.dump();
  };
  ExpectRefused(Parse(with_outputs("obstacles")), bad, "at most 8 entries");
  ExpectRefused(Parse(with_outputs(json::array({{{"name", "a"}},
                                                {{"name", "b"}},
                                                {{"name", "c"}},
                                                {{"name", "d"}},
                                                {{"name", "e"}},
                                                {{"name", "f"}},
                                                {{"name", "g"}},
                                                {{"name", "h"}},
                                                {{"name", "i"}}}))),
                bad, "at most 8 entries");
  ExpectRefused(Parse(with_outputs({{{"name", "obstacles"}}, {{"name", "obstacles"}}})), bad,
                "a second time");
  ExpectRefused(Parse(with_outputs({"obstacles"})), bad, "outputs[0] must be an object");
  ExpectRefused(Parse(with_outputs({{{"name", 3}}})), bad, "outputs[0] must be an object");
  ExpectRefused(
      Parse(with_outputs({{{"name", "obstacles"}, {"parameters", {{"binary_data", 1}}}}})), bad,
      "outputs[0].parameters.binary_data must be true or false");
}

TEST(OipTensorsTest, AnswersInJsonHaveFlatDataAndNoFramingHeader) {
  std::vector<OutputTensor> outputs;
  outputs.push_back({"boxes", {2, 2}, std::vector<float>{1, 2, 3, 4.5f}});
  outputs.push_back({"pixels", {1, 3}, std::vector<uint8_t>{0, 128, 255}});
  outputs.push_back({"png", {1}, std::vector<std::string>{kImage}});
  outputs.back().parameters = {{"format", "png"}};
  const EncodedResponse encoded =
      EncodeInferResponse({{"model_name", "m"}, {"model_version", "1"}, {"id", "x"}}, outputs);
  EXPECT_FALSE(encoded.header_length);
  const json body = json::parse(encoded.body);
  EXPECT_EQ(body["model_name"], "m");
  EXPECT_EQ(body["id"], "x");
  ASSERT_EQ(body["outputs"].size(), 3u);
  EXPECT_EQ(body["outputs"][0]["datatype"], "FP32");
  EXPECT_EQ(body["outputs"][0]["shape"], json({2, 2}));
  EXPECT_EQ(body["outputs"][0]["data"], json({1.0, 2.0, 3.0, 4.5}));
  EXPECT_FALSE(body["outputs"][0].contains("parameters"));
  EXPECT_EQ(body["outputs"][1]["datatype"], "UINT8");
  EXPECT_EQ(body["outputs"][1]["data"], json({0, 128, 255}));
  EXPECT_EQ(body["outputs"][2]["datatype"], "BYTES");
  EXPECT_EQ(body["outputs"][2]["data"][0], Base64Encode(kImage));
  EXPECT_EQ(body["outputs"][2]["parameters"]["format"], "png");
}

TEST(OipTensorsTest, BinaryOutputsFollowTheJsonLittleEndianWithTheirSizes) {
  std::vector<OutputTensor> outputs;
  outputs.push_back({"boxes", {1, 2}, std::vector<float>{1.0f, -2.5f}});
  outputs.back().binary = true;
  outputs.push_back({"json_too", {1}, std::vector<float>{7}});
  outputs.push_back({"png", {1}, std::vector<std::string>{kImage}});
  outputs.back().binary = true;
  const EncodedResponse encoded = EncodeInferResponse({{"model_name", "m"}}, outputs);
  ASSERT_TRUE(encoded.header_length);
  const json body = json::parse(encoded.body.substr(0, *encoded.header_length));
  EXPECT_EQ(body["outputs"][0]["parameters"]["binary_data_size"], 8);
  EXPECT_FALSE(body["outputs"][0].contains("data"));
  EXPECT_EQ(body["outputs"][1]["data"], json({7.0}));
  EXPECT_EQ(body["outputs"][2]["parameters"]["binary_data_size"], 4 + kImage.size());
  const std::string binary = encoded.body.substr(*encoded.header_length);
  ASSERT_EQ(binary.size(), 8 + 4 + kImage.size());
  // 1.0f = 0x3f800000, -2.5f = 0xc0200000, least significant byte first.
  EXPECT_EQ(binary.substr(0, 8), std::string("\x00\x00\x80\x3f\x00\x00\x20\xc0", 8));
  EXPECT_EQ(binary.substr(8, 4), LittleEndian32(kImage.size()));
  EXPECT_EQ(binary.substr(12), kImage);

  // An empty binary tensor (no obstacles) still frames the answer.
  std::vector<OutputTensor> empty;
  empty.push_back({"boxes", {0, 9}, std::vector<float>{}});
  empty.back().binary = true;
  const EncodedResponse none = EncodeInferResponse({{"model_name", "m"}}, empty);
  ASSERT_TRUE(none.header_length);
  EXPECT_EQ(*none.header_length, none.body.size());
  EXPECT_EQ(json::parse(none.body)["outputs"][0]["parameters"]["binary_data_size"], 0);
}

TEST(OipTensorsTest, Base64RoundTripsAndRefusesWhatIsNotBase64) {
  for (const std::string& text : {std::string(), std::string("A"), std::string("AB"),
                                  std::string("ABC"), kImage, std::string(1000, '\xff')}) {
    const Result<std::string> decoded = Base64Decode(Base64Encode(text), 1 << 20);
    ASSERT_TRUE(decoded.ok()) << decoded.status().message();
    EXPECT_EQ(*decoded, text);
  }
  EXPECT_EQ(Base64Encode("A"), "QQ==");
  EXPECT_EQ(*Base64Decode("QQ", 10), "A");  // unpadded
  EXPECT_EQ(*Base64Decode("QUI", 10), "AB");
  EXPECT_FALSE(Base64Decode("Q", 10).ok());
  EXPECT_FALSE(Base64Decode("QQ=", 10).ok());
  EXPECT_FALSE(Base64Decode("Q===", 10).ok());
  EXPECT_FALSE(Base64Decode("QQ==QQ==", 10).ok());
  EXPECT_FALSE(Base64Decode("QU I=", 10).ok());
  EXPECT_FALSE(Base64Decode("-_-_", 10).ok());  // URL-safe alphabet
  EXPECT_EQ(Base64Decode("QUJD", 2).status().code(), StatusCode::kResourceExhausted);
}

TEST(OipTensorsTest, ModelPathsParseAndEverythingElseIsNoPath) {
  std::optional<ModelPath> path = ParseModelPath("/v2/models/tiny");
  ASSERT_TRUE(path);
  EXPECT_EQ(path->name, "tiny");
  EXPECT_FALSE(path->version);
  EXPECT_EQ(path->action, ModelAction::kMetadata);
  path = ParseModelPath("/v2/models/my%20model/versions/tod-2026%2B1/infer");
  ASSERT_TRUE(path);
  EXPECT_EQ(path->name, "my model");
  EXPECT_EQ(path->version, "tod-2026+1");
  EXPECT_EQ(path->action, ModelAction::kInfer);
  path = ParseModelPath("/v2/models/tiny/ready");
  ASSERT_TRUE(path);
  EXPECT_EQ(path->action, ModelAction::kReady);
  path = ParseModelPath("/v2/models/tiny/versions/3");
  ASSERT_TRUE(path);
  EXPECT_EQ(path->version, "3");
  EXPECT_EQ(path->action, ModelAction::kMetadata);
  for (const char* bad :
       {"/v2/models/", "/v2/models//ready", "/v2/models/tiny/", "/v2/models/tiny/explain",
        "/v2/models/tiny/versions", "/v2/models/tiny/versions/", "/v2/models/tiny/versions/1/x",
        "/v2/models/tiny/versions/1/infer/more", "/v2/models/tiny/infer/more", "/v2/models/%4",
        "/v2/models/%zz", "/v2/models/a%", "/v2/model/tiny", "/v1/models/tiny"}) {
    EXPECT_FALSE(ParseModelPath(bad)) << bad;
  }
}

}  // namespace
}  // namespace tod::server::oip
