// The access log of both front ends: one line per finished detection request (gRPC Detect and
// DetectStream frames, REST /v1/detect and /v1/probability-map), and its count and duration in
// tod_requests_total / tod_request_duration_seconds. The front ends fill an AccessRecord; this is
// the one place that decides the line's fields and level.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "server/metrics.h"

namespace tod::server {

struct AccessRecord {
  std::string event;                 // the log message: "detect" | "probability-map"
  std::string protocol;              // "grpc" | "http"
  std::string id;                    // the server's request id ("g12", "h7")
  std::optional<std::string> path;   // REST: the request path
  std::string frame;                 // the frame id
  std::string peer;                  // the client's address
  size_t bytes = 0;                  // the request's image (REST: body) bytes
  nlohmann::json status;             // gRPC: the code name; REST: the HTTP status number
  std::string code;                  // the gRPC code name the metrics count
  double ms = 0;                     // admission to answer
  std::optional<std::string> error;  // set: logged, and the line is a warning
  const char* cancelled = nullptr;   // CancelReasonName, when the request's work was stopped
};

// The line's fields: id, protocol, [path], frame, peer, bytes, status, ms, [error], [cancelled].
nlohmann::json AccessLogFields(const AccessRecord& record);

// Counts the request in `metrics` (protocol, code, seconds) and logs its line: info, or warn when
// it has an error.
void LogAccess(const AccessRecord& record, ServerMetrics& metrics);

}  // namespace tod::server
