#include "server/http/http_types.h"

#include <nlohmann/json.hpp>

namespace tod::server::http {

Response JsonErrorResponse(unsigned http_status, std::string_view code, std::string_view message) {
  const nlohmann::json body = {{"error",
                                {{"code", std::string(code)},
                                 {"http_status", http_status},
                                 {"message", std::string(message)}}}};
  return ContentResponse(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                         "application/json", http_status);
}

Response ContentResponse(std::string body, std::string_view content_type, unsigned http_status) {
  Response response;
  response.result(http_status);
  response.set(beast_http::field::content_type, content_type);
  response.body() = std::move(body);
  return response;
}

}  // namespace tod::server::http
