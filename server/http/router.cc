#include "server/http/router.h"

namespace tod::server::http {

std::string_view TargetPath(std::string_view target) { return target.substr(0, target.find('?')); }

void Router::Add(beast_http::verb method, std::string path, RequestHandler handler) {
  routes_[std::move(path)].emplace_back(method, std::move(handler));
}

Router::Match Router::Find(beast_http::verb method, std::string_view target) const {
  Match match;
  const auto route = routes_.find(TargetPath(target));
  if (route == routes_.end()) {
    match.refused = RefusalReason::kNotFound;
    return match;
  }
  for (const auto& [route_method, handler] : route->second) {
    if (route_method == method) {
      match.handler = &handler;
      return match;
    }
    if (!match.allow.empty()) match.allow += ", ";
    match.allow += std::string(beast_http::to_string(route_method));
  }
  match.refused = RefusalReason::kMethodNotAllowed;
  return match;
}

}  // namespace tod::server::http
