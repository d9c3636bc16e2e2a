// The bodies of POST /v2/models/{name}/infer (Open Inference Protocol, REST) as values: the
// request, JSON alone or JSON followed by binary tensor data (the binary tensor data extension),
// parsed into what the detector needs, and the answer encoded the same two ways. Pure functions
// of bytes, no network and no engine, so every refusal is unit-tested
// (tests/server/oip_tensors_test.cc).
//
// Everything in a request body is hostile: its framing header, JSON size, nesting, value count,
// array lengths, shape values and base64 length are checked against fixed bounds before anything
// is allocated for them, and binary sizes must add up exactly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/base/status.h"
#include "server/rest_options.h"

namespace tod::server::oip {

// The HTTP header of the binary tensor data extension: the length of the JSON at the body's
// start; the binary tensor data follows it.
inline constexpr char kHeaderLengthField[] = "Inference-Header-Content-Length";

// The model's one input: the encoded frame (JPEG/PNG/...), one BYTES element.
inline constexpr char kImageInput[] = "image";

struct BodyLimits {
  size_t max_image_bytes = 16u << 20;  // the image's bytes (after base64 decoding)
  // The JSON: nesting and number of values (every scalar, key, array and object counts one).
  // A valid request needs depth 4 and a few dozen values; these leave room and no more.
  int max_json_depth = 8;
  size_t max_json_values = 512;
  size_t max_outputs = 8;  // entries of "outputs" (the model has three)
  size_t max_rank = 4;     // entries of an input's "shape"
};

// How the probability map is returned: a PNG in one BYTES element, or the 8-bit pixels.
enum class MapFormat { kPng, kUint8 };

struct RequestedOutput {
  std::string name;
  bool binary = false;  // parameters.binary_data (or the request's binary_data_output)
};

struct InferRequest {
  std::optional<std::string> id;  // echoed in the answer
  // The detection options of the request's parameters, as strings keyed like the /v1/detect
  // query, so that rest_options.h's ParseDetectQuery is the one parser and range check of both.
  QueryParams options;
  MapFormat map_format = MapFormat::kPng;
  std::vector<RequestedOutput> outputs;  // empty: every output
  bool binary_data_output = false;       // the default of outputs not listed (all of them)

  // The image: a view into the request body (binary extension) or the decoded base64 text.
  std::string_view image() const { return binary_image ? *binary_image : decoded_image; }
  std::string decoded_image;
  std::optional<std::string_view> binary_image;
};

// Whether a request parameter of this name is a detection option, passed to ParseDetectQuery
// (max_proposals, obstacle_threshold, min_obstacle_score, budget_ms, map_kind, timeout_ms,
// frame_id).
bool IsDetectOption(std::string_view name);

// The map_format parameter: "png" or "uint8"; InvalidArgument otherwise.
Result<MapFormat> ParseMapFormat(std::string_view text);

// The image in the binary form of one BYTES element: a 4-byte little-endian length, then that
// many bytes, filling `data` exactly and within limits.max_image_bytes. `where` names the tensor
// in messages.
Result<std::string_view> OnlyBytesElement(std::string_view data, const std::string& where,
                                          const BodyLimits& limits);

// Parses an infer request body. `header_length` is the Inference-Header-Content-Length value
// (nullopt: the body is all JSON). The returned request may view into `body`, which must outlive
// it. Refusals are InvalidArgument (malformed, inconsistent) or ResourceExhausted (over a
// bound), with a message naming the field.
Result<InferRequest> ParseInferRequest(std::string_view body,
                                       std::optional<std::string_view> header_length,
                                       const BodyLimits& limits);

// An output tensor; its datatype follows from the data: FP32, UINT8 or BYTES.
using TensorData = std::variant<std::vector<float>, std::vector<uint8_t>, std::vector<std::string>>;
struct OutputTensor {
  std::string name;
  std::vector<int64_t> shape;
  TensorData data;
  bool binary = false;  // sent after the JSON instead of in its "data"
  nlohmann::json parameters = nlohmann::json::object();
};

const char* Datatype(const TensorData& data);

// The tensor's binary form: little-endian FP32, UINT8 bytes, or each BYTES element prefixed by
// its 4-byte little-endian length (the binary tensor data extension and gRPC's raw contents).
std::string BinaryTensorData(const TensorData& data);

struct EncodedResponse {
  std::string body;
  // Set when binary outputs follow the JSON: the Inference-Header-Content-Length to send.
  std::optional<size_t> header_length;
};

// `head` (model_name, model_version, id, parameters) plus the outputs, in the order given. JSON
// data is flat, row-major; BYTES elements in JSON are base64. Binary data is little-endian, a
// BYTES element prefixed by its 4-byte length, each output's size in its binary_data_size.
EncodedResponse EncodeInferResponse(nlohmann::json head, const std::vector<OutputTensor>& outputs);

}  // namespace tod::server::oip
