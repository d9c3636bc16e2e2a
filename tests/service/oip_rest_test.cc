// End-to-end: the Open Inference Protocol (KServe v2) REST API of the real tod_server, with curl
// as the client (an independent HTTP implementation; base64 by coreutils): metadata, readiness,
// inference in JSON and with the binary tensor data extension both ways, errors in the
// protocol's form, and bearer tokens. Inference must agree with /v1/detect on the same frame.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/service/server_harness.h"
#include "tests/service/shared_server_test.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::RunCommand;
using testing::ServerProcess;
using testing::TestModel;

constexpr char kToken[] = "oip-token-0123456789abcdef";
// Limits the shared server runs with; the error tests go just over them.
constexpr int kMaxBytes = 400'000;
constexpr int kMaxPixels = 700 * 400;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

void WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

struct CurlAnswer {
  int status = 0;  // 0: curl failed (see output)
  std::string body;
  std::map<std::string, std::string> headers;  // lower-case names
  std::string output;

  std::string Header(const std::string& name) const {  // lower-case name; "" when absent
    const auto found = headers.find(name);
    return found == headers.end() ? "" : found->second;
  }
};

// One request with curl: `method` on `path` of the server's REST port, the body (if any) from a
// file, `headers` as "Name: value". No retries and no timing: --max-time only stops a hang.
CurlAnswer Curl(int port, const std::string& method, const std::string& path,
                const std::optional<std::string>& body = std::nullopt,
                const std::vector<std::string>& headers = {}) {
  const std::string dir = testing::MakeTempDir("tod_oip_curl");
  std::vector<std::string> argv = {
      "curl", "-s",          "-S", "--max-time",     "300", "-X",          method,
      "-o",   dir + "/body", "-D", dir + "/headers", "-w",  "%{http_code}"};
  if (body) {
    WriteFile(dir + "/request", *body);
    argv.insert(argv.end(), {"--data-binary", "@" + dir + "/request"});
  }
  for (const std::string& header : headers) argv.insert(argv.end(), {"-H", header});
  argv.push_back("http://127.0.0.1:" + std::to_string(port) + path);
  const testing::ProcessResult run = RunCommand(argv);
  CurlAnswer answer;
  answer.output = run.output;
  if (run.exit_code != 0) return answer;
  answer.status = std::atoi(run.output.c_str());
  answer.body = ReadFile(dir + "/body");
  std::istringstream lines(ReadFile(dir + "/headers"));
  for (std::string line; std::getline(lines, line);) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    std::string value = line.substr(colon + 1);
    while (!value.empty() && (value.front() == ' ')) value.erase(0, 1);
    while (!value.empty() && (value.back() == '\r' || value.back() == ' ')) value.pop_back();
    answer.headers[name] = value;
  }
  fs::remove_all(dir);
  return answer;
}

// Base64 by coreutils, so the test does not check the server's codec with itself.
std::string Base64(const std::string& bytes) {
  const std::string dir = testing::MakeTempDir("tod_oip_b64");
  WriteFile(dir + "/in", bytes);
  const testing::ProcessResult run = RunCommand({"base64", "-w0", dir + "/in"});
  fs::remove_all(dir);
  return run.exit_code == 0 ? run.output : "";
}
std::string Unbase64(const std::string& text) {
  const std::string dir = testing::MakeTempDir("tod_oip_b64");
  WriteFile(dir + "/in", text);
  const testing::ProcessResult run =
      RunCommand({"bash", "-c", "base64 -d '" + dir + "/in' > '" + dir + "/out'"});
  const std::string bytes = run.exit_code == 0 ? ReadFile(dir + "/out") : "";
  fs::remove_all(dir);
  return bytes;
}

std::string LittleEndian32(uint32_t value) {
  std::string out(4, '\0');
  for (int i = 0; i < 4; ++i) out[i] = static_cast<char>(value >> (8 * i));
  return out;
}
uint32_t ReadLittleEndian32(std::string_view bytes) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = (value << 8) | static_cast<unsigned char>(bytes[i]);
  return value;
}
std::vector<float> Floats(std::string_view bytes) {
  std::vector<float> out;
  for (size_t i = 0; i + 4 <= bytes.size(); i += 4) {
    out.push_back(std::bit_cast<float>(ReadLittleEndian32(bytes.substr(i, 4))));
  }
  return out;
}

std::string ModelName() { return fs::path(TestModel()).filename().string(); }

json JsonInfer(const std::string& image, json extra = json::object()) {
  json request = {
      {"inputs",
       {{{"name", "image"}, {"datatype", "BYTES"}, {"shape", {1}}, {"data", {Base64(image)}}}}}};
  request.update(extra);
  return request;
}

// A binary-extension request: the JSON header, then the image as one BYTES element. Returns the
// body; `header_length` is set.
std::string BinaryInfer(const std::string& image, json extra, size_t* header_length) {
  const std::string element = LittleEndian32(static_cast<uint32_t>(image.size())) + image;
  json header = {{"inputs",
                  {{{"name", "image"},
                    {"datatype", "BYTES"},
                    {"shape", {1}},
                    {"parameters", {{"binary_data_size", element.size()}}}}}}};
  header.update(extra);
  const std::string text = header.dump();
  *header_length = text.size();
  return text + element;
}

// The output named `name` of an infer answer's JSON.
json Output(const json& answer, const std::string& name) {
  for (const json& output : answer["outputs"]) {
    if (output["name"] == name) return output;
  }
  return json();
}

// The binary part of each output of a binary-extension answer, by name.
std::map<std::string, std::string> BinaryParts(const CurlAnswer& answer, json* head) {
  std::map<std::string, std::string> parts;
  const auto length = answer.headers.find("inference-header-content-length");
  if (length == answer.headers.end()) return parts;
  const size_t json_size = std::stoul(length->second);
  *head = json::parse(answer.body.substr(0, json_size));
  size_t offset = json_size;
  for (const json& output : (*head)["outputs"]) {
    if (!output.contains("parameters") || !output["parameters"].contains("binary_data_size")) {
      continue;
    }
    const size_t size = output["parameters"]["binary_data_size"].get<size_t>();
    parts[output["name"]] = answer.body.substr(offset, size);
    offset += size;
  }
  EXPECT_EQ(offset, answer.body.size()) << "the binary sizes must cover the body exactly";
  return parts;
}

// The /v1 answer's obstacles and proposals as the OIP rows (oip_model.h columns).
std::vector<float> V1Obstacles(const json& v1) {
  std::vector<float> rows;
  for (const json& o : v1["obstacles"]) {
    for (const char* key : {"x", "y", "w", "h"}) rows.push_back(o["box"][key].get<float>());
    for (const char* key : {"score", "peak_probability", "mean_probability", "evidence", "area"}) {
      rows.push_back(o[key].get<float>());
    }
  }
  return rows;
}
std::vector<float> V1Proposals(const json& v1) {
  std::vector<float> rows;
  for (const json& p : v1["proposals"]) {
    for (const char* key : {"x", "y", "w", "h"}) rows.push_back(p["box"][key].get<float>());
    for (const char* key : {"fused", "ordr", "obdr"}) rows.push_back(p[key].get<float>());
  }
  return rows;
}
std::vector<float> JsonFloats(const json& data) {
  std::vector<float> out;
  for (const json& value : data) out.push_back(value.get<float>());
  return out;
}

class OipRestTest : public testing::SharedServerTest<OipRestTest> {
 public:
  static std::vector<std::string> ServerArgs() {
    return {"--workers",          "2",
            "--max-image-bytes",  std::to_string(kMaxBytes),
            "--max-image-pixels", std::to_string(kMaxPixels)};
  }

 protected:
  int port() const { return server_->http_port(); }
  std::string ModelPath(const std::string& rest = "") const {
    return "/v2/models/" + ModelName() + rest;
  }
  // The /v1 answer for `frame`, the reference the OIP answers must match.
  json V1Detect(const std::string& frame) const {
    const CurlAnswer v1 =
        Curl(port(), "POST", "/v1/detect?map=none", frame, {"Content-Type: image/png"});
    EXPECT_EQ(v1.status, 200) << v1.output << v1.body;
    return v1.status == 200 ? json::parse(v1.body) : json();
  }
};

TEST_F(OipRestTest, ServerAndModelMetadata) {
  const CurlAnswer server = Curl(port(), "GET", "/v2");
  ASSERT_EQ(server.status, 200) << server.output << server.body;
  EXPECT_EQ(server.Header("content-type"), "application/json");
  const json metadata = json::parse(server.body);
  EXPECT_EQ(metadata["name"], "tod");
  EXPECT_TRUE(metadata["version"].is_string());
  EXPECT_EQ(metadata["extensions"], json({"binary_tensor_data"}));

  const CurlAnswer model = Curl(port(), "GET", ModelPath());
  ASSERT_EQ(model.status, 200) << model.body;
  const json info = json::parse(model.body);
  EXPECT_EQ(info["name"], ModelName());
  ASSERT_EQ(info["versions"].size(), 1u);
  const std::string version = info["versions"][0];
  EXPECT_FALSE(version.empty());
  EXPECT_EQ(info["inputs"], json::parse(R"([{"name":"image","datatype":"BYTES","shape":[1]}])"));
  ASSERT_EQ(info["outputs"].size(), 3u);
  EXPECT_EQ(info["outputs"][0]["name"], "obstacles");
  EXPECT_EQ(info["outputs"][0]["datatype"], "FP32");
  EXPECT_EQ(info["outputs"][1]["name"], "proposals");
  EXPECT_EQ(info["outputs"][2]["name"], "probability_map");
  EXPECT_EQ(model.body.find(TestModel()), std::string::npos) << "server path leaked";

  // The version path answers the same; another version or name is the protocol's 404.
  const CurlAnswer versioned = Curl(port(), "GET", ModelPath("/versions/" + version));
  ASSERT_EQ(versioned.status, 200) << versioned.body;
  EXPECT_EQ(json::parse(versioned.body), info);
  for (const std::string& path :
       {ModelPath("/versions/no-such-version"), std::string("/v2/models/no-such-model"),
        std::string("/v2/models/no-such-model/ready")}) {
    const CurlAnswer missing = Curl(port(), "GET", path);
    EXPECT_EQ(missing.status, 404) << path;
    const json error = json::parse(missing.body);
    ASSERT_TRUE(error["error"].is_string()) << missing.body;
    EXPECT_NE(error["error"].get<std::string>().find("no-such"), std::string::npos);
  }
  // The API is open without a token when the server has none.
  EXPECT_EQ(Curl(port(), "GET", ModelPath("/ready")).status, 200);
}

TEST_F(OipRestTest, ModelReadyAndTheHealthProbes) {
  const CurlAnswer ready = Curl(port(), "GET", ModelPath("/ready"));
  ASSERT_EQ(ready.status, 200) << ready.body;
  EXPECT_EQ(json::parse(ready.body), json({{"name", ModelName()}, {"ready", true}}));
  const json info = json::parse(Curl(port(), "GET", ModelPath()).body);
  const std::string version = info["versions"][0];
  EXPECT_EQ(Curl(port(), "GET", ModelPath("/versions/" + version + "/ready")).status, 200);
  EXPECT_EQ(Curl(port(), "GET", "/v2/health/live").status, 200);
  EXPECT_EQ(Curl(port(), "GET", "/v2/health/ready").status, 200);
}

TEST_F(OipRestTest, JsonInferenceMatchesV1Detect) {
  const std::string frame = testing::RoadPng();
  const json v1 = V1Detect(frame);
  ASSERT_FALSE(v1.is_null());
  const CurlAnswer map =
      Curl(port(), "POST", "/v1/probability-map", frame, {"Content-Type: image/png"});
  ASSERT_EQ(map.status, 200);

  const json request =
      JsonInfer(frame, {{"id", "req-42"}, {"parameters", {{"frame_id", "cam0-7"}}}});
  const CurlAnswer answer =
      Curl(port(), "POST", ModelPath("/infer"), request.dump(), {"Content-Type: application/json"});
  ASSERT_EQ(answer.status, 200) << answer.output << answer.body;
  EXPECT_EQ(answer.Header("content-type"), "application/json");
  EXPECT_EQ(answer.headers.count("inference-header-content-length"), 0u);
  const json body = json::parse(answer.body);
  EXPECT_EQ(body["model_name"], ModelName());
  EXPECT_EQ(body["model_version"], v1["model_version"]);
  EXPECT_EQ(body["id"], "req-42");
  EXPECT_EQ(body["parameters"]["frame_id"], "cam0-7");
  EXPECT_EQ(body["parameters"]["width"], 320);
  EXPECT_EQ(body["parameters"]["height"], 160);

  const json obstacles = Output(body, "obstacles");
  EXPECT_EQ(obstacles["datatype"], "FP32");
  EXPECT_EQ(obstacles["shape"], json({v1["obstacles"].size(), 9}));
  EXPECT_EQ(JsonFloats(obstacles["data"]), V1Obstacles(v1));
  const json proposals = Output(body, "proposals");
  EXPECT_EQ(proposals["shape"], json({v1["proposals"].size(), 7}));
  ASSERT_FALSE(v1["proposals"].empty());
  EXPECT_EQ(JsonFloats(proposals["data"]), V1Proposals(v1));
  const json probability = Output(body, "probability_map");
  EXPECT_EQ(probability["datatype"], "BYTES");
  ASSERT_EQ(probability["data"].size(), 1u);
  EXPECT_EQ(Unbase64(probability["data"][0]), map.body);  // the same PNG as /v1

  // Options: max_proposals as on /v1, one output selected.
  const json limited = JsonInfer(
      frame, {{"parameters", {{"max_proposals", 2}}}, {"outputs", {{{"name", "proposals"}}}}});
  const CurlAnswer few = Curl(port(), "POST", ModelPath("/infer"), limited.dump());
  ASSERT_EQ(few.status, 200) << few.body;
  const json few_body = json::parse(few.body);
  ASSERT_EQ(few_body["outputs"].size(), 1u);
  EXPECT_EQ(few_body["outputs"][0]["name"], "proposals");
  EXPECT_LE(few_body["outputs"][0]["shape"][0].get<int>(), 2);

  const std::optional<double> ok =
      testing::MetricValue(server_->Metrics(), R"(tod_requests_total{code="OK",protocol="http"})");
  EXPECT_GE(ok.value_or(0), 4);  // /v1 x2 + infer x2, counted like /v1
}

TEST_F(OipRestTest, BinaryExtensionInAndOutMatchesJsonAndV1) {
  const std::string frame = testing::RoadPng();
  const json v1 = V1Detect(frame);
  ASSERT_FALSE(v1.is_null());
  const CurlAnswer map =
      Curl(port(), "POST", "/v1/probability-map", frame, {"Content-Type: image/png"});
  ASSERT_EQ(map.status, 200);

  size_t header_length = 0;
  const std::string body = BinaryInfer(
      frame, {{"id", "bin-1"}, {"parameters", {{"binary_data_output", true}}}}, &header_length);
  const CurlAnswer answer =
      Curl(port(), "POST", ModelPath("/infer"), body,
           {"Content-Type: application/octet-stream",
            "Inference-Header-Content-Length: " + std::to_string(header_length)});
  ASSERT_EQ(answer.status, 200) << answer.output << answer.body;
  EXPECT_EQ(answer.Header("content-type"), "application/octet-stream");
  json head;
  const std::map<std::string, std::string> parts = BinaryParts(answer, &head);
  ASSERT_EQ(parts.size(), 3u) << answer.body.substr(0, 2000);
  EXPECT_EQ(head["id"], "bin-1");
  EXPECT_EQ(Floats(parts.at("obstacles")), V1Obstacles(v1));
  EXPECT_EQ(Floats(parts.at("proposals")), V1Proposals(v1));
  const std::string& element = parts.at("probability_map");
  ASSERT_GE(element.size(), 4u);
  EXPECT_EQ(ReadLittleEndian32(element), element.size() - 4);
  EXPECT_EQ(element.substr(4), map.body);

  // The map as UINT8 pixels, binary, next to a JSON output: the PNG's pixels exactly.
  const std::string pixels_request =
      BinaryInfer(frame,
                  {{"parameters", {{"map_format", "uint8"}}},
                   {"outputs",
                    {{{"name", "probability_map"}, {"parameters", {{"binary_data", true}}}},
                     {{"name", "obstacles"}}}}},
                  &header_length);
  const CurlAnswer pixels =
      Curl(port(), "POST", ModelPath("/infer"), pixels_request,
           {"Inference-Header-Content-Length: " + std::to_string(header_length)});
  ASSERT_EQ(pixels.status, 200) << pixels.body;
  const std::map<std::string, std::string> pixel_parts = BinaryParts(pixels, &head);
  ASSERT_EQ(pixel_parts.size(), 1u);
  const json map_output = Output(head, "probability_map");
  EXPECT_EQ(map_output["datatype"], "UINT8");
  EXPECT_EQ(map_output["shape"], json({160, 320}));
  const cv::Mat decoded =
      cv::imdecode(std::vector<uchar>(map.body.begin(), map.body.end()), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(decoded.type(), CV_8UC1);
  ASSERT_TRUE(decoded.isContinuous());
  EXPECT_EQ(pixel_parts.at("probability_map"),
            std::string(reinterpret_cast<const char*>(decoded.data), decoded.total()));
  EXPECT_EQ(JsonFloats(Output(head, "obstacles")["data"]), V1Obstacles(v1));
}

TEST_F(OipRestTest, ErrorsAreTheProtocolsJsonWithTheV1Codes) {
  const std::string frame = testing::RoadPng();
  struct Case {
    std::string what;
    std::string path;
    std::string body;
    std::vector<std::string> headers;
    int status;
    std::string message_part;
  };
  const std::string infer = "/v2/models/" + ModelName() + "/infer";
  size_t header_length = 0;
  const std::string binary = BinaryInfer(frame, json::object(), &header_length);
  const std::string framing = "Inference-Header-Content-Length: ";
  const std::vector<Case> cases = {
      {"unknown model", "/v2/models/nope/infer", JsonInfer(frame).dump(), {}, 404, "nope"},
      {"malformed JSON", infer, "{\"inputs\": [", {}, 400, "malformed"},
      {"empty body", infer, "", {}, 400, "empty"},
      {"two inputs",
       infer,
       json{{"inputs", {JsonInfer(frame)["inputs"][0], JsonInfer(frame)["inputs"][0]}}}.dump(),
       {},
       400,
       "one input"},
      {"unknown output",
       infer,
       JsonInfer(frame, {{"outputs", {{{"name", "boxes"}}}}}).dump(),
       {},
       400,
       "boxes"},
      {"option out of range",
       infer,
       JsonInfer(frame, {{"parameters", {{"max_proposals", 99999}}}}).dump(),
       {},
       400,
       "max_proposals"},
      {"not an image", infer, JsonInfer("not an image at all").dump(), {}, 400, "not a"},
      {"image over the pixel limit",
       infer,
       JsonInfer(testing::RoadPng(701, 400)).dump(),
       {},
       413,
       "pixels"},
      {"framing header not a number",
       infer,
       binary,
       {framing + "twelve"},
       400,
       "Inference-Header-Content-Length"},
      {"framing header past the body",
       infer,
       binary,
       {framing + std::to_string(binary.size() + 1)},
       400,
       "not within the body"},
      {"framing header given twice",
       infer,
       binary,
       {framing + std::to_string(header_length), framing + std::to_string(header_length)},
       400,
       "more than once"},
      {"binary data without framing", infer, binary, {}, 400, "malformed"},
      {"framing cuts the JSON",
       infer,
       binary,
       {framing + std::to_string(header_length - 3)},
       400,
       "malformed"},
  };
  for (const Case& c : cases) {
    const CurlAnswer answer = Curl(port(), "POST", c.path, c.body, c.headers);
    ASSERT_EQ(answer.status, c.status) << c.what << ": " << answer.output << answer.body;
    EXPECT_EQ(answer.Header("content-type"), "application/json") << c.what;
    const json error = json::parse(answer.body, nullptr, false);
    ASSERT_TRUE(!error.is_discarded() && error["error"].is_string())
        << c.what << ": " << answer.body;
    EXPECT_NE(error["error"].get<std::string>().find(c.message_part), std::string::npos)
        << c.what << ": " << answer.body;
  }
  // Wrong methods name the allowed one; unknown model paths are 404.
  CurlAnswer answer = Curl(port(), "GET", infer);
  EXPECT_EQ(answer.status, 405);
  EXPECT_EQ(answer.Header("allow"), "POST");
  answer = Curl(port(), "POST", ModelPath("/ready"), "{}");
  EXPECT_EQ(answer.status, 405);
  EXPECT_EQ(answer.Header("allow"), "GET");
  answer = Curl(port(), "GET", ModelPath("/explain"));
  EXPECT_EQ(answer.status, 404);
  EXPECT_TRUE(json::parse(answer.body)["error"].is_string()) << answer.body;
  answer = Curl(port(), "DELETE", ModelPath());
  EXPECT_EQ(answer.status, 405);
  // A body over the byte limit is refused by the transport before any handler runs: 413 in the
  // transport's (the /v1) error form.
  answer = Curl(port(), "POST", infer, std::string(kMaxBytes + 10, ' '));
  EXPECT_EQ(answer.status, 413) << answer.body;
  // /v1 is as it was.
  EXPECT_EQ(Curl(port(), "GET", "/v1/nothing-here").status, 404);
  EXPECT_EQ(Curl(port(), "GET", "/v1/detect").status, 405);
  // And the server still serves.
  EXPECT_EQ(Curl(port(), "POST", infer, JsonInfer(frame).dump()).status, 200);
}

// With --auth-token-file the API needs the token; the probes stay open.
TEST(OipRestAuthTest, TokenRequiredOnTheApiProbesOpen) {
  REQUIRE_MODEL();
  const std::string dir = testing::MakeTempDir("tod_oip_auth");
  WriteFile(dir + "/tokens", std::string(kToken) + "\n");
  const auto server =
      ServerProcess::Start(TestModel(), {"--workers", "1", "--auth-token-file", dir + "/tokens"});
  ASSERT_TRUE(server->WaitReady()) << server->Log();
  const int port = server->http_port();
  const std::string model = "/v2/models/" + ModelName();
  const std::string bearer = std::string("Authorization: Bearer ") + kToken;
  const std::string frame = testing::RoadPng();
  const std::string request = JsonInfer(frame).dump();

  struct Call {
    std::string method;
    std::string path;
    std::optional<std::string> body;
  };
  const std::vector<Call> api = {{"GET", "/v2", std::nullopt},
                                 {"GET", model, std::nullopt},
                                 {"GET", model + "/ready", std::nullopt},
                                 {"POST", model + "/infer", request},
                                 {"GET", "/v2/models/other", std::nullopt}};
  for (const Call& call : api) {
    for (const std::string& token :
         {std::string(), std::string("Authorization: Bearer wrong-token-0123456789")}) {
      std::vector<std::string> headers;
      if (!token.empty()) headers.push_back(token);
      const CurlAnswer refused = Curl(port, call.method, call.path, call.body, headers);
      EXPECT_EQ(refused.status, 401) << call.path << " " << token << ": " << refused.body;
      EXPECT_EQ(refused.Header("www-authenticate"), "Bearer") << call.path;
    }
  }
  EXPECT_EQ(Curl(port, "GET", "/v2", std::nullopt, {bearer}).status, 200);
  EXPECT_EQ(Curl(port, "GET", model, std::nullopt, {bearer}).status, 200);
  EXPECT_EQ(Curl(port, "GET", model + "/ready", std::nullopt, {bearer}).status, 200);
  EXPECT_EQ(Curl(port, "GET", "/v2/models/other", std::nullopt, {bearer}).status, 404);
  const CurlAnswer inferred = Curl(port, "POST", model + "/infer", request, {bearer});
  EXPECT_EQ(inferred.status, 200) << inferred.body;
  EXPECT_EQ(Curl(port, "POST", "/v1/detect?map=none", frame, {"Content-Type: image/png"}).status,
            401);
  // Probes and the scraper need no token.
  EXPECT_EQ(Curl(port, "GET", "/v2/health/live").status, 200);
  EXPECT_EQ(Curl(port, "GET", "/v2/health/ready").status, 200);
  EXPECT_EQ(Curl(port, "GET", "/metrics").status, 200);
}

}  // namespace
}  // namespace tod::server
