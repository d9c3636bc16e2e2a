#include "server/oip/oip_model.h"

#include <algorithm>
#include <array>
#include <opencv2/core.hpp>

#include "server/rest_options.h"

#ifndef TOD_SERVER_VERSION
#define TOD_SERVER_VERSION "unknown"
#endif

namespace tod::server::oip {
namespace {

using nlohmann::json;

constexpr std::array<std::string_view, 3> kOutputs = {kObstaclesOutput, kProposalsOutput,
                                                      kMapOutput};
constexpr char kObstacleColumns[] = "x,y,w,h,score,peak_probability,mean_probability,evidence,area";
constexpr char kProposalColumns[] = "x,y,w,h,fused,ordr,obdr";
constexpr int kObstacleWidth = 9;
constexpr int kProposalWidth = 7;

void AppendBox(const Box& box, std::vector<float>* row) {
  row->insert(row->end(), {static_cast<float>(box.x), static_cast<float>(box.y),
                           static_cast<float>(box.w), static_cast<float>(box.h)});
}

OutputTensor Obstacles(const Detection& detection) {
  std::vector<float> data;
  data.reserve(detection.obstacles.size() * kObstacleWidth);
  for (const DetectedObstacle& obstacle : detection.obstacles) {
    AppendBox(obstacle.box, &data);
    data.insert(data.end(), {obstacle.score, obstacle.peak_probability, obstacle.mean_probability,
                             obstacle.evidence, static_cast<float>(obstacle.area)});
  }
  OutputTensor tensor{kObstaclesOutput,
                      {static_cast<int64_t>(detection.obstacles.size()), kObstacleWidth},
                      std::move(data)};
  tensor.parameters = {{"columns", kObstacleColumns}};
  return tensor;
}

OutputTensor Proposals(const Detection& detection) {
  std::vector<float> data;
  data.reserve(detection.proposals.size() * kProposalWidth);
  for (const Proposal& proposal : detection.proposals) {
    AppendBox(proposal.box, &data);
    data.insert(data.end(), {proposal.fused, proposal.ordr, proposal.obdr});
  }
  OutputTensor tensor{kProposalsOutput,
                      {static_cast<int64_t>(detection.proposals.size()), kProposalWidth},
                      std::move(data)};
  tensor.parameters = {{"columns", kProposalColumns}};
  return tensor;
}

Result<OutputTensor> Map(const InferRequest& request, const InferenceResult& result) {
  if (request.map_format == MapFormat::kPng) {
    if (result.map_png.empty()) return Status::Internal("the pipeline produced no map");
    return OutputTensor{kMapOutput, {1}, std::vector<std::string>{result.map_png}};
  }
  const cv::Mat1f& probability = result.detection.probability;
  if (probability.empty()) return Status::Internal("the pipeline produced no map");
  // The PNG's pixels exactly (image_codec.h): round(255 * P), saturated to 0..255.
  cv::Mat1b pixels;
  probability.convertTo(pixels, CV_8U, 255.0);
  std::vector<uint8_t> data(pixels.total());
  for (int row = 0; row < pixels.rows; ++row) {
    std::copy_n(pixels.ptr<uint8_t>(row), pixels.cols, data.begin() + row * pixels.cols);
  }
  return OutputTensor{kMapOutput, {pixels.rows, pixels.cols}, std::move(data)};
}

json TensorMetadata(std::string_view name, std::string_view datatype, std::vector<int64_t> shape) {
  return {{"name", name}, {"datatype", datatype}, {"shape", std::move(shape)}};
}

}  // namespace

Result<std::shared_ptr<const LoadedModel>> ResolveModel(const ModelHolder& models,
                                                        std::string_view name,
                                                        std::optional<std::string_view> version) {
  if (models.empty()) return Status::Unavailable("model not loaded yet");
  std::shared_ptr<const LoadedModel> model = name.empty() ? nullptr : models.Find(name);
  if (!model) return Status::NotFound("unknown model '" + std::string(name) + "'");
  if (version && *version != ModelVersion(model->detector->info())) {
    return Status::NotFound("model '" + std::string(name) + "' has no version '" +
                            std::string(*version) + "'");
  }
  return model;
}

Status ApplyOptions(const InferRequest& request, InferenceRequest* inference,
                    std::string* frame_id) {
  const Status parsed = ParseDetectQuery(request.options, inference, frame_id);
  if (parsed.ok()) return parsed;  // (the options hold no "model": the path names it)
  // ParseDetectQuery names "query parameter x"; here x is a request parameter.
  std::string message = parsed.message();
  if (message.starts_with("query parameter ")) message.erase(0, 6);
  return Status::InvalidArgument(message);
}

std::string ModelVersion(const ModelInfo& info) {
  return info.version.empty() ? "1" : info.version;
}

json ServerMetadata() {
  return {{"name", "tod"}, {"version", TOD_SERVER_VERSION}, {"extensions", {"binary_tensor_data"}}};
}

json ModelMetadata(const ModelInfo& info) {
  json obstacles = TensorMetadata(kObstaclesOutput, "FP32", {-1, kObstacleWidth});
  obstacles["parameters"] = {{"columns", kObstacleColumns}};
  json proposals = TensorMetadata(kProposalsOutput, "FP32", {-1, kProposalWidth});
  proposals["parameters"] = {{"columns", kProposalColumns}};
  json map = TensorMetadata(kMapOutput, "BYTES", {1});
  map["parameters"] = {
      {"format", "png; UINT8 [H, W] when the request parameter map_format is uint8"}};
  return {{"name", info.name},
          {"versions", {ModelVersion(info)}},
          {"platform", "tod_pipeline"},
          {"inputs", {TensorMetadata(kImageInput, "BYTES", {1})}},
          {"outputs", {std::move(obstacles), std::move(proposals), std::move(map)}}};
}

Status CheckOutputs(const InferRequest& request) {
  for (const RequestedOutput& output : request.outputs) {
    if (std::find(kOutputs.begin(), kOutputs.end(), output.name) == kOutputs.end()) {
      return Status::InvalidArgument("the model has no output '" + output.name +
                                     "'; it has obstacles, proposals, probability_map");
    }
  }
  return Status::Ok();
}

bool WantsMap(const InferRequest& request) {
  return request.outputs.empty() ||
         std::any_of(request.outputs.begin(), request.outputs.end(),
                     [](const RequestedOutput& output) { return output.name == kMapOutput; });
}

Result<std::vector<OutputTensor>> BuildOutputs(const InferRequest& request,
                                               const InferenceResult& result) {
  std::vector<RequestedOutput> wanted = request.outputs;
  if (wanted.empty()) {
    for (const std::string_view name : kOutputs) {
      wanted.push_back({std::string(name), request.binary_data_output});
    }
  }
  std::vector<OutputTensor> outputs;
  for (const RequestedOutput& output : wanted) {
    Result<OutputTensor> tensor = Status::Internal("unknown output " + output.name);
    if (output.name == kObstaclesOutput) {
      tensor = Obstacles(result.detection);
    } else if (output.name == kProposalsOutput) {
      tensor = Proposals(result.detection);
    } else {
      tensor = Map(request, result);
    }
    if (!tensor.ok()) return tensor.status();
    tensor->binary = output.binary;
    outputs.push_back(std::move(*tensor));
  }
  return outputs;
}

json ResponseHead(const InferRequest& request, const InferenceResult& result,
                  const std::string& frame_id) {
  const Detection& detection = result.detection;
  std::string stages;
  for (const std::string& stage : detection.degraded_stages) {
    stages += (stages.empty() ? "" : ",") + stage;
  }
  json head = {
      {"model_name", result.model ? result.model->detector->info().name : ""},
      {"model_version", result.model ? ModelVersion(result.model->detector->info()) : ""},
      {"parameters",
       {{"frame_id", frame_id},
        {"width", detection.width},
        {"height", detection.height},
        {"map_kind", detection.map_kind == MapKind::kCalibrated ? "calibrated" : "normalized"},
        {"degraded", detection.degraded()},
        {"degraded_stages", stages},
        {"total_ms", result.total_ms}}}};
  if (request.id) head["id"] = *request.id;
  return head;
}

}  // namespace tod::server::oip
