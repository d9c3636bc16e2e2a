#include "server/oip/oip_errors.h"

#include "server/status_mapping.h"

namespace tod::server::oip {

std::string Dump(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

http::Response OipError(unsigned http_status, std::string_view message) {
  return http::ContentResponse(Dump({{"error", message}}), kJsonType, http_status);
}

http::Response OipError(const Status& status) {
  return OipError(HttpStatusFor(status, Rejection::kNone), status.message());
}

}  // namespace tod::server::oip
