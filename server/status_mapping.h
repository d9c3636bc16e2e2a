// One table from the engine's outcome to protocol codes (issue: API errors).
#pragma once

#include <grpcpp/support/status.h>

#include <string>

#include "core/base/status.h"
#include "server/core/inference_engine.h"

namespace tod::server {

grpc::StatusCode ToGrpcCode(StatusCode code);
grpc::Status ToGrpcStatus(const Status& status);
// "OK", "INVALID_ARGUMENT", ... (metrics labels and logs).
std::string GrpcCodeName(grpc::StatusCode code);
// 400, 413, 503, 504 ... for an engine result; the rejection separates a full queue (503, retry)
// from an oversized image (413).
int HttpStatusFor(const Status& status, Rejection rejection);

}  // namespace tod::server
