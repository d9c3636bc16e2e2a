// The Open Inference Protocol's REST answers as the two OIP front ends (oip_rest, oip_repository)
// send them: JSON that never throws on a client's bytes, and the error body {"error": "..."}.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "core/base/status.h"
#include "server/http/http_types.h"

namespace tod::server::oip {

inline constexpr char kJsonType[] = "application/json";

// Messages may quote a client's bytes (a %-decoded model name): invalid UTF-8 is replaced.
std::string Dump(const nlohmann::json& value);

// {"error": message} with `http_status`, or with the status code the Status maps to
// (server/status_mapping.h).
http::Response OipError(unsigned http_status, std::string_view message);
http::Response OipError(const Status& status);

}  // namespace tod::server::oip
