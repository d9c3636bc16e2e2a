#include "server/core/cancellation.h"

namespace tod::server {

const char* CancelReasonName(CancelReason reason) {
  switch (reason) {
    case CancelReason::kDeadline:
      return "deadline";
    case CancelReason::kClientCancelled:
      return "client_cancelled";
    case CancelReason::kClientDisconnected:
      return "client_disconnected";
    case CancelReason::kDrain:
      return "drain";
  }
  return "unknown";
}

Status CancelledStatus(CancelReason reason, const std::string& where) {
  switch (reason) {
    case CancelReason::kDeadline:
      return Status::DeadlineExceeded("deadline passed " + where + "; the work was stopped");
    case CancelReason::kClientCancelled:
      return Status::Cancelled("the client cancelled the call " + where + "; the work was stopped");
    case CancelReason::kClientDisconnected:
      return Status::Cancelled("the client disconnected " + where + "; the work was stopped");
    case CancelReason::kDrain:
      return Status::Unavailable("server is shutting down: the drain timeout came " + where +
                                 "; retry elsewhere");
  }
  return Status::Cancelled("cancelled " + where);
}

}  // namespace tod::server
