// Translation between the engine's values and the tod.v1 messages, shared by both frontends so
// gRPC and REST answer with the same content (REST is the JSON form of the same message,
// proto/json/message_json.h).
#pragma once

#include <string>

#include "core/base/status.h"
#include "server/core/inference_engine.h"
#include "server/core/model_holder.h"
#include "tod/v1/obstacle_discovery.pb.h"

namespace tod::server {

struct RequestOptions {
  DetectOptions detect;
  bool encode_map_png = true;
};

// Unset fields take the pipeline defaults (DetectOptions); range checks happen in the engine.
RequestOptions OptionsFromProto(const tod::v1::DetectOptions& options);

void FillDetectResponse(const InferenceResult& result, const std::string& frame_id,
                        tod::v1::DetectResponse* response);

// The geometry the detection stood on (DetectResponse.geometry).
void FillGeometry(const Detection& detection, tod::v1::Geometry* geometry);
void FillModelInfo(const LoadedModel& model, tod::v1::ModelInfo* info);

}  // namespace tod::server
