#include "server/http/refusal.h"

namespace tod::server::http {

const char* RefusalReasonName(RefusalReason reason) {
  switch (reason) {
    case RefusalReason::kBodyTooLarge:
      return "body_too_large";
    case RefusalReason::kHeaderTooLarge:
      return "header_too_large";
    case RefusalReason::kReadTimeout:
      return "read_timeout";
    case RefusalReason::kIdleTimeout:
      return "idle_timeout";
    case RefusalReason::kTooManyConnections:
      return "too_many_connections";
    case RefusalReason::kTooManyConnectionsPerClient:
      return "too_many_connections_per_client";
    case RefusalReason::kBufferBudget:
      return "buffer_budget";
    case RefusalReason::kLengthRequired:
      return "length_required";
    case RefusalReason::kMalformedRequest:
      return "malformed_request";
    case RefusalReason::kNotFound:
      return "not_found";
    case RefusalReason::kMethodNotAllowed:
      return "method_not_allowed";
    case RefusalReason::kWriteTimeout:
      return "write_timeout";
    case RefusalReason::kInternal:
      return "internal";
    case RefusalReason::kUnauthenticated:
      return "unauthenticated";
    case RefusalReason::kTlsHandshake:
      return "tls_handshake";
  }
  return "unknown";
}

unsigned RefusalHttpStatus(RefusalReason reason) {
  switch (reason) {
    case RefusalReason::kBodyTooLarge:
      return 413;
    case RefusalReason::kHeaderTooLarge:
      return 431;
    case RefusalReason::kReadTimeout:
      return 408;
    case RefusalReason::kTooManyConnections:
    case RefusalReason::kTooManyConnectionsPerClient:
    case RefusalReason::kBufferBudget:
      return 503;
    case RefusalReason::kLengthRequired:
      return 411;
    case RefusalReason::kMalformedRequest:
      return 400;
    case RefusalReason::kNotFound:
      return 404;
    case RefusalReason::kMethodNotAllowed:
      return 405;
    case RefusalReason::kInternal:
      return 500;
    case RefusalReason::kUnauthenticated:
      return 401;
    case RefusalReason::kIdleTimeout:
    case RefusalReason::kWriteTimeout:
    case RefusalReason::kTlsHandshake:
      return 0;
  }
  return 500;
}

const char* RefusalCodeName(RefusalReason reason) {
  switch (reason) {
    case RefusalReason::kBodyTooLarge:
    case RefusalReason::kHeaderTooLarge:
    case RefusalReason::kTooManyConnections:
    case RefusalReason::kTooManyConnectionsPerClient:
    case RefusalReason::kBufferBudget:
      return "RESOURCE_EXHAUSTED";
    case RefusalReason::kReadTimeout:
    case RefusalReason::kIdleTimeout:
    case RefusalReason::kWriteTimeout:
      return "DEADLINE_EXCEEDED";
    case RefusalReason::kLengthRequired:
    case RefusalReason::kMalformedRequest:
      return "INVALID_ARGUMENT";
    case RefusalReason::kNotFound:
      return "NOT_FOUND";
    case RefusalReason::kMethodNotAllowed:
      return "UNIMPLEMENTED";
    case RefusalReason::kInternal:
      return "INTERNAL";
    case RefusalReason::kUnauthenticated:
      return "UNAUTHENTICATED";
    case RefusalReason::kTlsHandshake:
      return "UNAVAILABLE";
  }
  return "UNKNOWN";
}

}  // namespace tod::server::http
