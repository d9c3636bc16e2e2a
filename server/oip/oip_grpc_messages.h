// The Open Inference Protocol's gRPC messages (proto/inference/grpc_service.proto) to and from the
// values the REST API uses (oip_tensors.h, oip_model.h), so that both protocols share one parser
// of options, one model description and one set of output tensors. Pure: no network, no engine;
// unit-tested in tests/server/oip_grpc_messages_test.cc.
//
// Input: the one BYTES tensor "image" of shape [1], its element either in raw_input_contents[0]
// (the binary form: a 4-byte little-endian length, then the encoded frame) or in
// contents.bytes_contents[0]. Outputs always go to raw_output_contents, in the binary form of
// the REST extension, as Triton and KServe clients expect over gRPC.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "core/base/status.h"
#include "inference/grpc_service.pb.h"
#include "server/oip/oip_tensors.h"

namespace tod::server::oip {

// The request as oip_tensors.h's InferRequest. Its image views into `message`, which must
// outlive it. InvalidArgument (malformed: names the field) or ResourceExhausted (over a bound).
Result<InferRequest> FromModelInferRequest(const inference::ModelInferRequest& message,
                                           const BodyLimits& limits);

// `head` (ResponseHead's model_name, model_version, id, parameters) and the outputs.
inference::ModelInferResponse ToModelInferResponse(const nlohmann::json& head,
                                                   const std::vector<OutputTensor>& outputs);

// ServerMetadata() and ModelMetadata(info) as their messages (the gRPC message has no place
// for the outputs' "columns" parameter; ModelInfer's outputs carry it).
inference::ServerMetadataResponse ToServerMetadataResponse(const nlohmann::json& metadata);
inference::ModelMetadataResponse ToModelMetadataResponse(const nlohmann::json& metadata);

}  // namespace tod::server::oip
