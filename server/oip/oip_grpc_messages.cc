#include "server/oip/oip_grpc_messages.h"

#include <cstdint>
#include <set>
#include <string>

namespace tod::server::oip {
namespace {

using nlohmann::json;
using Parameters = google::protobuf::Map<std::string, inference::InferParameter>;

// A detection option's value as the text ParseDetectQuery range-checks.
Result<std::string> OptionText(const std::string& name, const inference::InferParameter& value) {
  switch (value.parameter_choice_case()) {
    case inference::InferParameter::kStringParam:
      return value.string_param();
    case inference::InferParameter::kInt64Param:
      return std::to_string(value.int64_param());
    case inference::InferParameter::kUint64Param:
      return std::to_string(value.uint64_param());
    case inference::InferParameter::kDoubleParam:
      return json(value.double_param()).dump();  // the shortest text that reads back the same
    case inference::InferParameter::kBoolParam:
      return std::string(value.bool_param() ? "true" : "false");
    default:
      return Status::InvalidArgument("parameter " + name +
                                     " must be a number, a string or a boolean");
  }
}

// Detection options (for ParseDetectQuery) and the map format; other names are left alone, as
// the protocol lets parameters be extended.
Status ReadParameters(const Parameters& parameters, InferRequest* out) {
  for (const auto& [name, value] : parameters) {
    if (IsDetectOption(name)) {
      Result<std::string> text = OptionText(name, value);
      if (!text.ok()) return text.status();
      out->options[name] = std::move(*text);
    } else if (name == "map_format") {
      const Result<MapFormat> format =
          ParseMapFormat(value.parameter_choice_case() == inference::InferParameter::kStringParam
                             ? value.string_param()
                             : "");
      if (!format.ok()) return format.status();
      out->map_format = *format;
    }
  }
  return Status::Ok();
}

// How many elements the typed contents hold, over all their kinds.
int TypedElementCount(const inference::InferTensorContents& contents) {
  return contents.bool_contents_size() + contents.int_contents_size() +
         contents.int64_contents_size() + contents.uint_contents_size() +
         contents.uint64_contents_size() + contents.fp32_contents_size() +
         contents.fp64_contents_size() + contents.bytes_contents_size();
}

Status ReadInput(const inference::ModelInferRequest& message, const BodyLimits& limits,
                 InferRequest* out) {
  if (message.inputs_size() != 1) {
    return Status::InvalidArgument("the model has one input ('" + std::string(kImageInput) +
                                   "'); the request has " + std::to_string(message.inputs_size()));
  }
  const auto& input = message.inputs(0);
  const std::string where = "inputs[0]";
  if (input.name() != kImageInput) {
    return Status::InvalidArgument(where + ".name must be \"" + std::string(kImageInput) + "\"");
  }
  if (input.datatype() != "BYTES") {
    return Status::InvalidArgument(where + ".datatype must be \"BYTES\" (the encoded image)");
  }
  if (input.shape_size() != 1 || input.shape(0) != 1) {
    return Status::InvalidArgument(where + ".shape must be [1]: one image per request");
  }
  const int typed = TypedElementCount(input.contents());
  if (message.raw_input_contents_size() > 1) {
    return Status::InvalidArgument("raw_input_contents has " +
                                   std::to_string(message.raw_input_contents_size()) +
                                   " entries for one input");
  }
  if (message.raw_input_contents_size() == 1) {
    if (typed > 0) {
      return Status::InvalidArgument(where + " has both contents and raw_input_contents");
    }
    const Result<std::string_view> image =
        OnlyBytesElement(message.raw_input_contents(0), "raw_input_contents[0]", limits);
    if (!image.ok()) return image.status();
    out->binary_image = *image;
    return Status::Ok();
  }
  const auto& contents = input.contents();
  if (contents.bytes_contents_size() != 1 || typed != 1) {
    return Status::InvalidArgument(
        where +
        " must hold the image in contents.bytes_contents (one element) or in "
        "raw_input_contents");
  }
  const std::string& image = contents.bytes_contents(0);
  if (image.size() > limits.max_image_bytes) {
    return Status::ResourceExhausted(where + ": the image of " + std::to_string(image.size()) +
                                     " bytes is over the limit of " +
                                     std::to_string(limits.max_image_bytes) + " bytes");
  }
  out->binary_image = std::string_view(image);
  return Status::Ok();
}

Status ReadOutputs(const inference::ModelInferRequest& message, const BodyLimits& limits,
                   InferRequest* out) {
  if (static_cast<size_t>(message.outputs_size()) > limits.max_outputs) {
    return Status::InvalidArgument("\"outputs\" must have at most " +
                                   std::to_string(limits.max_outputs) + " entries");
  }
  std::set<std::string, std::less<>> seen;
  for (int i = 0; i < message.outputs_size(); ++i) {
    const std::string& name = message.outputs(i).name();
    if (!seen.insert(name).second) {
      return Status::InvalidArgument("outputs[" + std::to_string(i) + "] names '" + name +
                                     "' a second time");
    }
    out->outputs.push_back({name, /*binary=*/true});
  }
  return Status::Ok();
}

inference::InferParameter ToParameter(const json& value) {
  inference::InferParameter parameter;
  if (value.is_boolean()) {
    parameter.set_bool_param(value.get<bool>());
  } else if (value.is_number_unsigned() &&
             value.get<uint64_t>() > static_cast<uint64_t>(INT64_MAX)) {
    parameter.set_uint64_param(value.get<uint64_t>());  // only what int64 cannot hold
  } else if (value.is_number_integer()) {
    parameter.set_int64_param(value.get<int64_t>());
  } else if (value.is_number_float()) {
    parameter.set_double_param(value.get<double>());
  } else if (value.is_string()) {
    parameter.set_string_param(value.get<std::string>());
  } else {
    parameter.set_string_param(value.dump());
  }
  return parameter;
}

void FillParameters(const json& parameters, Parameters* out) {
  if (!parameters.is_object()) return;
  for (const auto& [name, value] : parameters.items()) (*out)[name] = ToParameter(value);
}

template <typename TensorMetadata>
void FillTensorMetadata(const json& tensor, TensorMetadata* out) {
  out->set_name(tensor.at("name").get<std::string>());
  out->set_datatype(tensor.at("datatype").get<std::string>());
  for (const json& dim : tensor.at("shape")) out->add_shape(dim.get<int64_t>());
}

}  // namespace

Result<InferRequest> FromModelInferRequest(const inference::ModelInferRequest& message,
                                           const BodyLimits& limits) {
  InferRequest out;
  if (!message.id().empty()) out.id = message.id();
  if (Status s = ReadParameters(message.parameters(), &out); !s.ok()) return s;
  if (Status s = ReadInput(message, limits, &out); !s.ok()) return s;
  if (Status s = ReadOutputs(message, limits, &out); !s.ok()) return s;
  out.binary_data_output = true;
  return out;
}

inference::ModelInferResponse ToModelInferResponse(const json& head,
                                                   const std::vector<OutputTensor>& outputs) {
  inference::ModelInferResponse response;
  response.set_model_name(head.value("model_name", ""));
  response.set_model_version(head.value("model_version", ""));
  response.set_id(head.value("id", ""));
  if (const auto it = head.find("parameters"); it != head.end()) {
    FillParameters(*it, response.mutable_parameters());
  }
  for (const OutputTensor& output : outputs) {
    auto* tensor = response.add_outputs();
    tensor->set_name(output.name);
    tensor->set_datatype(Datatype(output.data));
    for (const int64_t dim : output.shape) tensor->add_shape(dim);
    FillParameters(output.parameters, tensor->mutable_parameters());
    response.add_raw_output_contents(BinaryTensorData(output.data));
  }
  return response;
}

inference::ServerMetadataResponse ToServerMetadataResponse(const json& metadata) {
  inference::ServerMetadataResponse response;
  response.set_name(metadata.at("name").get<std::string>());
  response.set_version(metadata.at("version").get<std::string>());
  for (const json& extension : metadata.at("extensions")) {
    response.add_extensions(extension.get<std::string>());
  }
  return response;
}

inference::ModelMetadataResponse ToModelMetadataResponse(const json& metadata) {
  inference::ModelMetadataResponse response;
  response.set_name(metadata.at("name").get<std::string>());
  for (const json& version : metadata.at("versions")) {
    response.add_versions(version.get<std::string>());
  }
  response.set_platform(metadata.at("platform").get<std::string>());
  for (const json& input : metadata.at("inputs")) FillTensorMetadata(input, response.add_inputs());
  for (const json& output : metadata.at("outputs")) {
    FillTensorMetadata(output, response.add_outputs());
  }
  return response;
}

}  // namespace tod::server::oip
