// Why the HTTP layer refused a request or connection before (or instead of) the REST handlers,
// with the status and error code it answers. Every refusal is logged and counted by its reason.
#pragma once

#include <string>

namespace tod::server::http {

enum class RefusalReason {
  kBodyTooLarge,        // 413: body over max_body_bytes (declared or counted while reading)
  kHeaderTooLarge,      // 431: request line + header fields over max_header_bytes
  kReadTimeout,         // 408: the whole request did not arrive within request_timeout
  kIdleTimeout,         // no reply: a new connection sent nothing within idle_timeout
  kTooManyConnections,  // 503: max_connections open
  kTooManyConnectionsPerClient,  // 503: max_connections_per_client open from this address
  kBufferBudget,                 // 503: all connections together hold max_buffered_bytes
  kLengthRequired,               // 411: POST/PUT with neither Content-Length nor chunked body
  kMalformedRequest,             // 400: not parseable as HTTP/1.x
  kNotFound,                     // 404: no such path
  kMethodNotAllowed,             // 405 (+ Allow): the path exists, the method does not
  kWriteTimeout,                 // no reply: the client did not read its response
  kInternal,                     // 500: a handler threw
  kUnauthenticated,              // 401 (+ WWW-Authenticate): no or no valid bearer token
  kTlsHandshake,                 // no reply: the TLS handshake failed or did not finish in time
};

// Stable snake_case name: the `reason` label of tod_http_refused_total and the log field.
const char* RefusalReasonName(RefusalReason reason);
// The HTTP status sent (0: none can be sent, the connection is just closed).
unsigned RefusalHttpStatus(RefusalReason reason);
// The gRPC-style code name in the JSON error body, as the REST handlers use.
const char* RefusalCodeName(RefusalReason reason);

// One refusal, as reported to the server's observer.
struct Refusal {
  RefusalReason reason;
  std::string message;  // for the client and the log
  std::string peer;     // client address
  std::string target;   // request target when known
};

}  // namespace tod::server::http
