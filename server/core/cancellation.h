// Why a request's work was stopped before it finished, and the flag the front ends set when their
// caller gives up. One Cancellation is shared by the front end that admitted a request (which
// cancels it when the gRPC call is cancelled or the REST client disconnects) and the engine
// (which cancels it for deadlines and the drain timeout, and asks it at every stage boundary).
#pragma once

#include <atomic>
#include <optional>
#include <string>

#include "core/base/status.h"

namespace tod::server {

enum class CancelReason {
  kDeadline,            // the gRPC deadline or REST timeout_ms passed
  kClientCancelled,     // the gRPC client cancelled the call
  kClientDisconnected,  // the REST client closed its connection before the answer
  kDrain,               // the drain timeout came while the request was queued or running
};
// Stable lower-case name, the "reason" label of tod_requests_cancelled_total.
const char* CancelReasonName(CancelReason reason);
inline constexpr CancelReason kAllCancelReasons[] = {
    CancelReason::kDeadline, CancelReason::kClientCancelled, CancelReason::kClientDisconnected,
    CancelReason::kDrain};

// The Status a request stopped for `reason` completes with: DeadlineExceeded, Cancelled, or (for
// the drain) Unavailable, so that clients retry elsewhere. `where` says what was stopped.
Status CancelledStatus(CancelReason reason, const std::string& where);

// Thread-safe; the first reason wins (a call cancelled by the drain stays a drain cancellation
// when gRPC later reports the shutdown as a cancelled call).
class Cancellation {
 public:
  void Cancel(CancelReason reason) {
    int expected = kNone;
    reason_.compare_exchange_strong(expected, static_cast<int>(reason));
  }
  std::optional<CancelReason> reason() const {
    const int reason = reason_.load();
    if (reason == kNone) return std::nullopt;
    return static_cast<CancelReason>(reason);
  }
  bool cancelled() const { return reason_.load() != kNone; }

 private:
  static constexpr int kNone = -1;
  std::atomic<int> reason_{kNone};
};

}  // namespace tod::server
