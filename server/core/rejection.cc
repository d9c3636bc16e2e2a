#include "server/core/rejection.h"

namespace tod::server {

const char* RejectionName(Rejection rejection) {
  switch (rejection) {
    case Rejection::kNone:
      return "none";
    case Rejection::kNotReady:
      return "not_ready";
    case Rejection::kQueueFull:
      return "queue_full";
    case Rejection::kTooLarge:
      return "too_large";
    case Rejection::kBadImage:
      return "bad_image";
    case Rejection::kBadRequest:
      return "bad_request";
    case Rejection::kUnknownModel:
      return "unknown_model";
    case Rejection::kDeadline:
      return "deadline";
    case Rejection::kCancelled:
      return "cancelled";
    case Rejection::kInternal:
      return "internal";
  }
  return "unknown";
}

}  // namespace tod::server
