#include "server/http/router.h"

namespace tod::server::http {

std::string_view TargetPath(std::string_view target) { return target.substr(0, target.find('?')); }

void Router::Add(beast_http::verb method, std::string path, RequestHandler handler) {
  routes_[std::move(path)].emplace_back(method, std::move(handler));
}

void Router::AddPrefix(beast_http::verb method, std::string prefix, RequestHandler handler) {
  prefixes_[std::move(prefix)].emplace_back(method, std::move(handler));
}

Router::Match Router::Find(beast_http::verb method, std::string_view target) const {
  Match match;
  const std::string_view path = TargetPath(target);
  const Handlers* handlers = nullptr;
  if (const auto route = routes_.find(path); route != routes_.end()) {
    handlers = &route->second;
  } else {
    // Few prefixes: a scan, keeping the longest that matches.
    size_t longest = 0;
    for (const auto& [prefix, prefix_handlers] : prefixes_) {
      if (path.starts_with(prefix) && prefix.size() >= longest) {
        longest = prefix.size();
        handlers = &prefix_handlers;
      }
    }
  }
  if (!handlers) {
    match.refused = RefusalReason::kNotFound;
    return match;
  }
  for (const auto& [route_method, handler] : *handlers) {
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
