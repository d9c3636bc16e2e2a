#include "server/oip/oip_tensors.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <limits>
#include <set>

#include "server/oip/oip_base64.h"

namespace tod::server::oip {
namespace {

using nlohmann::json;

// The request parameters that are detection options: passed to ParseDetectQuery by these names.
constexpr std::array<std::string_view, 9> kDetectOptions = {
    "max_proposals", "obstacle_threshold", "min_obstacle_score", "budget_ms", "map_kind",
    "timeout_ms",    "frame_id",           "camera_id",          "calibrate"};

// Runs before the JSON becomes a document: counts values and nesting as the parser meets them
// and stops it at the first bound crossed, so a hostile body ("[[[[..." or a million tiny
// numbers) costs a few bytes of parser state, not a tree of millions of nodes.
class BoundedSax : public nlohmann::json_sax<json> {
 public:
  explicit BoundedSax(const BodyLimits& limits) : limits_(limits) {}

  bool null() override { return Value(); }
  bool boolean(bool) override { return Value(); }
  bool number_integer(number_integer_t) override { return Value(); }
  bool number_unsigned(number_unsigned_t) override { return Value(); }
  bool number_float(number_float_t, const string_t&) override { return Value(); }
  bool string(string_t&) override { return Value(); }
  bool binary(binary_t&) override { return Value(); }
  bool key(string_t&) override { return Value(); }
  bool start_object(std::size_t) override { return Open(); }
  bool end_object() override { return Close(); }
  bool start_array(std::size_t) override { return Open(); }
  bool end_array() override { return Close(); }
  bool parse_error(std::size_t position, const std::string&,
                   const nlohmann::detail::exception& e) override {
    // e.what() is "[json.exception.parse_error.101] parse error at line 1, column 7: ...".
    error_ = Status::InvalidArgument("the request JSON is malformed at byte " +
                                     std::to_string(position) + ": " + e.what());
    return false;
  }

  const Status& error() const { return error_; }

 private:
  bool Value() {
    if (++values_ > limits_.max_json_values) {
      error_ = Status::ResourceExhausted("the request JSON has more than " +
                                         std::to_string(limits_.max_json_values) + " values");
      return false;
    }
    return true;
  }
  bool Open() {
    if (++depth_ > limits_.max_json_depth) {
      error_ = Status::InvalidArgument("the request JSON nests deeper than " +
                                       std::to_string(limits_.max_json_depth) + " levels");
      return false;
    }
    return Value();
  }
  bool Close() {
    --depth_;
    return true;
  }

  const BodyLimits& limits_;
  size_t values_ = 0;
  int depth_ = 0;
  Status error_;
};

Result<size_t> ParseHeaderLength(std::string_view text, size_t body_size) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  uint64_t value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  // from_chars accepts no sign, so "-1" and "+1" fail here; an overlong number is out_of_range.
  if (text.empty() || ec != std::errc() || ptr != text.data() + text.size()) {
    return Status::InvalidArgument(std::string(kHeaderLengthField) + " '" +
                                   std::string(text.substr(0, 32)) + "' is not a byte count");
  }
  if (value == 0 || value > body_size) {
    return Status::InvalidArgument(std::string(kHeaderLengthField) + " " + std::to_string(value) +
                                   " is not within the body of " + std::to_string(body_size) +
                                   " bytes");
  }
  return static_cast<size_t>(value);
}

// `status` (InvalidArgument or ResourceExhausted) with `where` in front of its message.
Status WithContext(const Status& status, const std::string& where) {
  const std::string message = where + ": " + status.message();
  return status.code() == StatusCode::kResourceExhausted ? Status::ResourceExhausted(message)
                                                         : Status::InvalidArgument(message);
}

// The parameters object of `holder` (where: for messages), or an empty object when absent.
Result<const json*> Parameters(const json& holder, const std::string& where) {
  static const json kEmpty = json::object();
  const auto it = holder.find("parameters");
  if (it == holder.end()) return &kEmpty;
  if (!it->is_object()) return Status::InvalidArgument(where + ".parameters must be an object");
  return &*it;
}

Result<bool> BoolParameter(const json& parameters, const char* name, const std::string& where) {
  const auto it = parameters.find(name);
  if (it == parameters.end()) return false;
  if (!it->is_boolean()) {
    return Status::InvalidArgument(where + ".parameters." + name + " must be true or false");
  }
  return it->get<bool>();
}

// The request's parameters: detection options (as strings, for ParseDetectQuery), the map
// format and the binary_data_output default. Other names are left alone, as the protocol lets
// parameters be extended.
Status ReadRequestParameters(const json& request, InferRequest* out) {
  const Result<const json*> parameters = Parameters(request, "request");
  if (!parameters.ok()) return parameters.status();
  for (const auto& [name, value] : (*parameters)->items()) {
    if (IsDetectOption(name)) {
      if (value.is_string()) {
        out->options[name] = value.get<std::string>();
      } else if (value.is_number() || value.is_boolean()) {
        // The shortest text that reads back as the same number; ParseDetectQuery range-checks.
        out->options[name] = value.dump();
      } else {
        return Status::InvalidArgument("parameter " + name +
                                       " must be a number, a string or a boolean");
      }
    } else if (name == "map_format") {
      const Result<MapFormat> format =
          ParseMapFormat(value.is_string() ? value.get_ref<const std::string&>() : "");
      if (!format.ok()) return format.status();
      out->map_format = *format;
    }
  }
  const Result<bool> binary = BoolParameter(**parameters, "binary_data_output", "request");
  if (!binary.ok()) return binary.status();
  out->binary_data_output = *binary;
  return Status::Ok();
}

// shape: 1..max_rank integers in [0, 2^31), whose product is the element count.
Result<uint64_t> ElementCount(const json& input, const std::string& where,
                              const BodyLimits& limits) {
  const auto shape = input.find("shape");
  if (shape == input.end() || !shape->is_array() || shape->empty() ||
      shape->size() > limits.max_rank) {
    return Status::InvalidArgument(where + ".shape must be an array of 1 to " +
                                   std::to_string(limits.max_rank) + " integers");
  }
  uint64_t count = 1;
  for (const json& dim : *shape) {
    constexpr int64_t kMaxDim = std::numeric_limits<int32_t>::max();
    if (!dim.is_number_integer() || dim.get<int64_t>() < 0 || dim.get<int64_t>() > kMaxDim) {
      return Status::InvalidArgument(where + ".shape holds " + dim.dump() +
                                     ", not an integer in 0.." + std::to_string(kMaxDim));
    }
    // Each factor is below 2^31 and the product is capped at 2^31 before the next multiplication,
    // so this cannot overflow 64 bits.
    count = std::min<uint64_t>(count * static_cast<uint64_t>(dim.get<int64_t>()), 1ull << 31);
  }
  return count;
}

// The one element of a JSON "data": flat (["..."]) or nested as the shape is ([["..."]]).
Result<std::string_view> OnlyJsonElement(const json& data, const std::string& where,
                                         const BodyLimits& limits) {
  const json* element = &data;
  for (size_t level = 0; element->is_array(); ++level) {
    if (element->size() != 1 || level == limits.max_rank) {
      return Status::InvalidArgument(where + ".data must hold exactly one element");
    }
    element = &element->front();
  }
  if (!element->is_string()) {
    return Status::InvalidArgument(where + ".data must hold the image as a base64 string");
  }
  return std::string_view(element->get_ref<const std::string&>());
}

// inputs: exactly one, the BYTES image, in JSON (base64) or as binary data (the rest of the body,
// `binary`; null without the extension's header).
Status ReadInput(const json& request, std::optional<std::string_view> binary,
                 const BodyLimits& limits, InferRequest* out) {
  const auto inputs = request.find("inputs");
  if (inputs == request.end() || !inputs->is_array()) {
    return Status::InvalidArgument("the request has no \"inputs\" array");
  }
  if (inputs->size() != 1) {
    return Status::InvalidArgument("the model has one input ('" + std::string(kImageInput) +
                                   "'); the request has " + std::to_string(inputs->size()));
  }
  const json& input = inputs->front();
  const std::string where = "inputs[0]";
  if (!input.is_object()) return Status::InvalidArgument(where + " must be an object");
  const auto name = input.find("name");
  if (name == input.end() || !name->is_string() || *name != kImageInput) {
    return Status::InvalidArgument(where + ".name must be \"" + std::string(kImageInput) + "\"");
  }
  const auto datatype = input.find("datatype");
  if (datatype == input.end() || !datatype->is_string() || *datatype != "BYTES") {
    return Status::InvalidArgument(where + ".datatype must be \"BYTES\" (the encoded image)");
  }
  const Result<uint64_t> count = ElementCount(input, where, limits);
  if (!count.ok()) return count.status();
  if (*count != 1) {
    return Status::InvalidArgument(where + ".shape must be [1]: one image per request");
  }
  const Result<const json*> parameters = Parameters(input, where);
  if (!parameters.ok()) return parameters.status();
  const auto size = (*parameters)->find("binary_data_size");
  const bool has_data = input.contains("data");

  if (size == (*parameters)->end()) {
    if (binary) {
      return Status::InvalidArgument(std::to_string(binary->size()) +
                                     " bytes follow the JSON header but no input claims them "
                                     "with parameters.binary_data_size");
    }
    if (!has_data) return Status::InvalidArgument(where + " has neither data nor binary data");
    const Result<std::string_view> text = OnlyJsonElement(*input.find("data"), where, limits);
    if (!text.ok()) return text.status();
    Result<std::string> image = Base64Decode(*text, limits.max_image_bytes);
    if (!image.ok()) return WithContext(image.status(), where);
    out->decoded_image = std::move(*image);
    return Status::Ok();
  }

  if (has_data) {
    return Status::InvalidArgument(where + " has both data and parameters.binary_data_size");
  }
  if (!size->is_number_unsigned()) {
    return Status::InvalidArgument(where +
                                   ".parameters.binary_data_size must be a non-negative integer");
  }
  if (!binary) {
    return Status::InvalidArgument(where + ".parameters.binary_data_size needs the " +
                                   std::string(kHeaderLengthField) +
                                   " header (the length of the JSON before the binary data)");
  }
  const uint64_t declared = size->get<uint64_t>();
  if (declared != binary->size()) {
    return Status::InvalidArgument(
        where + ".parameters.binary_data_size is " + std::to_string(declared) + " but " +
        std::to_string(binary->size()) + " bytes follow the JSON header");
  }
  const Result<std::string_view> image = OnlyBytesElement(*binary, where, limits);
  if (!image.ok()) return image.status();
  out->binary_image = *image;
  return Status::Ok();
}

// outputs: at most max_outputs distinct names, each optionally binary. Whether a name exists is
// the model's business (oip_model.h).
Status ReadOutputs(const json& request, const BodyLimits& limits, InferRequest* out) {
  const auto outputs = request.find("outputs");
  if (outputs == request.end()) return Status::Ok();
  if (!outputs->is_array() || outputs->size() > limits.max_outputs) {
    return Status::InvalidArgument("\"outputs\" must be an array of at most " +
                                   std::to_string(limits.max_outputs) + " entries");
  }
  std::set<std::string, std::less<>> seen;
  for (size_t i = 0; i < outputs->size(); ++i) {
    const json& output = (*outputs)[i];
    const std::string where = "outputs[" + std::to_string(i) + "]";
    const auto name = output.is_object() ? output.find("name") : output.end();
    if (!output.is_object() || name == output.end() || !name->is_string()) {
      return Status::InvalidArgument(where + " must be an object with a \"name\"");
    }
    if (!seen.insert(name->get<std::string>()).second) {
      return Status::InvalidArgument(where + " names '" + name->get<std::string>() +
                                     "' a second time");
    }
    const Result<const json*> parameters = Parameters(output, where);
    if (!parameters.ok()) return parameters.status();
    const Result<bool> binary = BoolParameter(**parameters, "binary_data", where);
    if (!binary.ok()) return binary.status();
    // An output without its own binary_data takes the request's binary_data_output.
    const bool explicit_binary = (*parameters)->contains("binary_data");
    out->outputs.push_back({name->get<std::string>(), explicit_binary ? *binary : false});
    if (!explicit_binary) out->outputs.back().binary = out->binary_data_output;
  }
  return Status::Ok();
}

void AppendLittleEndian32(uint32_t value, std::string* out) {
  for (int shift = 0; shift < 32; shift += 8) out->push_back(static_cast<char>(value >> shift));
}

json JsonData(const TensorData& data) {
  if (const auto* floats = std::get_if<std::vector<float>>(&data)) return json(*floats);
  if (const auto* bytes = std::get_if<std::vector<uint8_t>>(&data)) return json(*bytes);
  json elements = json::array();
  for (const std::string& element : std::get<std::vector<std::string>>(data)) {
    elements.push_back(Base64Encode(element));
  }
  return elements;
}

}  // namespace

bool IsDetectOption(std::string_view name) {
  return std::find(kDetectOptions.begin(), kDetectOptions.end(), name) != kDetectOptions.end();
}

Result<MapFormat> ParseMapFormat(std::string_view text) {
  if (text == "png") return MapFormat::kPng;
  if (text == "uint8") return MapFormat::kUint8;
  return Status::InvalidArgument("parameter map_format must be \"png\" or \"uint8\"");
}

Result<std::string_view> OnlyBytesElement(std::string_view data, const std::string& where,
                                          const BodyLimits& limits) {
  if (data.size() < 4) {
    return Status::InvalidArgument(where + ": " + std::to_string(data.size()) +
                                   " bytes of binary data cannot hold a BYTES element (a 4-byte "
                                   "length comes first)");
  }
  const uint32_t length = static_cast<uint32_t>(static_cast<unsigned char>(data[0])) |
                          static_cast<uint32_t>(static_cast<unsigned char>(data[1])) << 8 |
                          static_cast<uint32_t>(static_cast<unsigned char>(data[2])) << 16 |
                          static_cast<uint32_t>(static_cast<unsigned char>(data[3])) << 24;
  if (length != data.size() - 4) {
    return Status::InvalidArgument(where + ": the BYTES element declares " +
                                   std::to_string(length) + " bytes but its binary data holds " +
                                   std::to_string(data.size() - 4) + " after the length");
  }
  if (length > limits.max_image_bytes) {
    return Status::ResourceExhausted(where + ": the image of " + std::to_string(length) +
                                     " bytes is over the limit of " +
                                     std::to_string(limits.max_image_bytes) + " bytes");
  }
  return data.substr(4);
}

std::string BinaryTensorData(const TensorData& data) {
  std::string out;
  if (const auto* floats = std::get_if<std::vector<float>>(&data)) {
    out.reserve(floats->size() * 4);
    for (const float value : *floats) AppendLittleEndian32(std::bit_cast<uint32_t>(value), &out);
  } else if (const auto* bytes = std::get_if<std::vector<uint8_t>>(&data)) {
    out.assign(bytes->begin(), bytes->end());
  } else {
    for (const std::string& element : std::get<std::vector<std::string>>(data)) {
      AppendLittleEndian32(static_cast<uint32_t>(element.size()), &out);
      out.append(element);
    }
  }
  return out;
}

Result<InferRequest> ParseInferRequest(std::string_view body,
                                       std::optional<std::string_view> header_length,
                                       const BodyLimits& limits) {
  std::string_view text = body;
  std::optional<std::string_view> binary;
  if (header_length) {
    const Result<size_t> length = ParseHeaderLength(*header_length, body.size());
    if (!length.ok()) return length.status();
    text = body.substr(0, *length);
    if (*length < body.size()) binary = body.substr(*length);
  }
  if (text.empty()) return Status::InvalidArgument("the request body is empty");

  BoundedSax bounds(limits);
  if (!json::sax_parse(text, &bounds)) return bounds.error();
  // Within the bounds and well formed: now it may become a document.
  const json request = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (request.is_discarded() || !request.is_object()) {
    return Status::InvalidArgument("the request JSON must be an object");
  }

  InferRequest out;
  if (const auto id = request.find("id"); id != request.end()) {
    if (!id->is_string()) return Status::InvalidArgument("\"id\" must be a string");
    out.id = id->get<std::string>();
  }
  if (Status s = ReadRequestParameters(request, &out); !s.ok()) return s;
  if (Status s = ReadInput(request, binary, limits, &out); !s.ok()) return s;
  if (Status s = ReadOutputs(request, limits, &out); !s.ok()) return s;
  return out;
}

const char* Datatype(const TensorData& data) {
  if (std::holds_alternative<std::vector<float>>(data)) return "FP32";
  if (std::holds_alternative<std::vector<uint8_t>>(data)) return "UINT8";
  return "BYTES";
}

EncodedResponse EncodeInferResponse(json head, const std::vector<OutputTensor>& outputs) {
  std::string binary;
  json& listed = head["outputs"] = json::array();
  for (const OutputTensor& output : outputs) {
    json entry = {
        {"name", output.name}, {"datatype", Datatype(output.data)}, {"shape", output.shape}};
    json parameters = output.parameters;
    if (output.binary) {
      const std::string data = BinaryTensorData(output.data);
      parameters["binary_data_size"] = data.size();
      binary += data;
    } else {
      entry["data"] = JsonData(output.data);
    }
    if (!parameters.empty()) entry["parameters"] = std::move(parameters);
    listed.push_back(std::move(entry));
  }
  EncodedResponse response;
  // Invalid UTF-8 cannot come from a parsed request, but a replacement beats an exception.
  response.body = head.dump(-1, ' ', false, json::error_handler_t::replace);
  if (!binary.empty() ||
      std::any_of(outputs.begin(), outputs.end(), [](const OutputTensor& o) { return o.binary; })) {
    response.header_length = response.body.size();
    response.body += binary;
  }
  return response;
}

}  // namespace tod::server::oip
