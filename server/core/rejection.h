// Why a request did not produce a detection: the engine's verdict, which the front ends map onto
// protocol codes (server/status_mapping.h) and the metrics count by name.
#pragma once

namespace tod::server {

enum class Rejection {
  kNone,
  kNotReady,    // no model yet, or draining          -> UNAVAILABLE / 503
  kQueueFull,   //                                    -> RESOURCE_EXHAUSTED / 503 + Retry-After
  kTooLarge,    // byte or pixel limit                -> RESOURCE_EXHAUSTED / 413
  kBadImage,    // empty / undecodable                -> INVALID_ARGUMENT / 400
  kBadRequest,  // invalid option                     -> INVALID_ARGUMENT / 400
  kUnknownModel,  // no model of the request's name     -> NOT_FOUND / 404
  kDeadline,    // deadline passed (queued or running) -> DEADLINE_EXCEEDED / 504
  kCancelled,   // client gone, or the drain timeout   -> CANCELLED / 499, UNAVAILABLE / 503
  kInternal,    // pipeline failure                   -> INTERNAL / 500
};
// Stable lower-case name, used as the metrics label "reason".
const char* RejectionName(Rejection rejection);

}  // namespace tod::server
