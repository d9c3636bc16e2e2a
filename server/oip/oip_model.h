// The served detector as an Open Inference Protocol model: its name and version, its metadata
// (one BYTES input, three outputs) and the output tensors of a detection. Pure: no network.
//
//   name     the bundle's directory name (ModelInfo::name, what /v1/model calls name)
//   version  the manifest's "version" string, or "1" when the manifest has none
//   input    image            BYTES [1]     the encoded frame (JPEG/PNG)
//   outputs  obstacles        FP32  [N, 9]  x, y, w, h, score, peak_probability,
//                                           mean_probability, evidence, area
//            proposals        FP32  [M, 7]  x, y, w, h, fused, ordr, obdr (best first)
//            probability_map  BYTES [1]     8-bit grey PNG; with map_format=uint8: UINT8 [H, W]
// Rows are the /v1 answer's obstacles and proposals in the same order, with the same values
// (boxes in pixels of the frame; area in pixels, exact in FP32 below 2^24).
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/detector.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "server/oip/oip_tensors.h"

namespace tod::server::oip {

inline constexpr char kObstaclesOutput[] = "obstacles";
inline constexpr char kProposalsOutput[] = "proposals";
inline constexpr char kMapOutput[] = "probability_map";

// The loaded model when `name` (and `version`, when given) name it: Unavailable before a model
// is loaded, NotFound for another name or version.
Result<std::shared_ptr<const LoadedModel>> ResolveModel(const ModelHolder& models,
                                                        std::string_view name,
                                                        std::optional<std::string_view> version);

// The protocol's model version of a bundle.
std::string ModelVersion(const ModelInfo& info);

// GET /v2: {"name": "tod", "version": ..., "extensions": [...]}.
nlohmann::json ServerMetadata();

// GET /v2/models/{name}: name, versions, platform, inputs, outputs, parameters (the columns).
nlohmann::json ModelMetadata(const ModelInfo& info);

// An infer request may ask for these outputs only (InvalidArgument naming the first other one).
Status CheckOutputs(const InferRequest& request);

// The request's detection options (its parameters, named like the /v1/detect query) into
// `inference` and `frame_id`; InvalidArgument naming the parameter when one is out of range.
Status ApplyOptions(const InferRequest& request, InferenceRequest* inference,
                    std::string* frame_id);

// Whether the request's outputs include the probability map (else the engine skips it).
bool WantsMap(const InferRequest& request);

// The outputs the request asks for, in its order (all three when it names none). Internal when
// the map was asked for and the pipeline made none.
Result<std::vector<OutputTensor>> BuildOutputs(const InferRequest& request,
                                               const InferenceResult& result);

// model_name, model_version, id (when the request had one) and parameters: frame_id, width,
// height, map_kind, degraded, degraded_stages (comma-separated), total_ms.
nlohmann::json ResponseHead(const InferRequest& request, const InferenceResult& result,
                            const std::string& frame_id);

}  // namespace tod::server::oip
