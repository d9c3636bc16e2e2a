#include "server/logging.h"

#include <spdlog/sinks/stdout_sinks.h>

#include <algorithm>
#include <atomic>

namespace tod::server {
namespace {

std::atomic<bool> json_format{false};

// Dumps without throwing on invalid UTF-8 (client-supplied text may contain any bytes).
std::string Dump(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string TextValue(const nlohmann::json& value) {
  if (value.is_string()) {
    const std::string& text = value.get_ref<const std::string&>();
    // Quote (JSON-escape) values with spaces or control characters, so key=value stays
    // splittable and a client's text (a frame_id of "%0A...") cannot start a forged log line.
    const bool plain = std::none_of(text.begin(), text.end(),
                                    [](unsigned char c) { return c <= ' ' || c == 0x7f; });
    return plain ? text : Dump(nlohmann::json(text));
  }
  return Dump(value);
}

}  // namespace

Status SetUpLogging(const std::string& format, const std::string& level) {
  if (format != "text" && format != "json") {
    return Status::InvalidArgument("log_format: '" + format + "' is not text or json");
  }
  const spdlog::level::level_enum parsed = spdlog::level::from_str(level);
  spdlog::drop("tod_server");
  auto logger = spdlog::stderr_logger_mt("tod_server");
  json_format = format == "json";
  // JSON: the payload (%v) is the rest of an object that LogEvent writes already escaped.
  logger->set_pattern(json_format ? R"({"time":"%Y-%m-%dT%H:%M:%S.%fZ","level":"%l",%v})"
                                  : "%Y-%m-%dT%H:%M:%S.%fZ %l %v",
                      spdlog::pattern_time_type::utc);
  logger->set_level(parsed);
  logger->flush_on(spdlog::level::info);
  spdlog::set_default_logger(logger);
  return Status::Ok();
}

void LogEvent(spdlog::level::level_enum level, std::string_view message,
              const nlohmann::json& fields) {
  if (!spdlog::should_log(level)) return;
  std::string line;
  if (json_format) {
    // Appends piece by piece (also sidesteps GCC 12's false -Wrestrict on "literal" + string).
    line.append("\"msg\":").append(Dump(nlohmann::json(std::string(message))));
    for (const auto& [key, value] : fields.items()) {
      line.append(",").append(Dump(nlohmann::json(key))).append(":").append(Dump(value));
    }
  } else {
    line = std::string(message);
    for (const auto& [key, value] : fields.items()) {
      line.append(" ").append(key).append("=").append(TextValue(value));
    }
  }
  spdlog::log(level, "{}", line);
}

}  // namespace tod::server
