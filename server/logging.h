// Structured logs through spdlog: one line per event, as "text" (message key=value ...) or as one
// JSON object per line ("json"), so log collectors can parse request lines.
#pragma once

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "core/base/status.h"

namespace tod::server {

// Configures the default spdlog logger (stderr). format: "text" | "json".
Status SetUpLogging(const std::string& format, const std::string& level);

// Logs `message` with `fields` in the configured format.
void LogEvent(spdlog::level::level_enum level, std::string_view message,
              const nlohmann::json& fields = nlohmann::json::object());

}  // namespace tod::server
