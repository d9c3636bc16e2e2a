// Maps (method, path) to a handler. A path that exists with other methods is 405 with the methods
// it has (for the Allow header); an unknown path is 404. Matching only: the connection answers.
// Exact paths come first; a prefix route takes every other path starting with its prefix (the
// longest prefix wins), for APIs with names in their paths that the handler parses itself.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "server/http/http_types.h"
#include "server/http/refusal.h"

namespace tod::server::http {

class Router {
 public:
  void Add(beast_http::verb method, std::string path, RequestHandler handler);
  void AddPrefix(beast_http::verb method, std::string prefix, RequestHandler handler);

  struct Match {
    const RequestHandler* handler = nullptr;  // set when found
    std::optional<RefusalReason> refused;     // kNotFound or kMethodNotAllowed
    std::string allow;                        // for 405: "GET, POST"
  };
  // `target` may carry a query string; only the path before '?' is matched.
  Match Find(beast_http::verb method, std::string_view target) const;

 private:
  using Handlers = std::vector<std::pair<beast_http::verb, RequestHandler>>;
  // path -> (method, handler); few routes, so a vector per path is plenty.
  std::map<std::string, Handlers, std::less<>> routes_;
  std::map<std::string, Handlers, std::less<>> prefixes_;
};

// The path part of a request target ("/v1/detect?x=1" -> "/v1/detect").
std::string_view TargetPath(std::string_view target);

}  // namespace tod::server::http
