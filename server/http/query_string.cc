#include "server/http/query_string.h"

#include "server/http/percent_decoding.h"

namespace tod::server::http {

std::map<std::string, std::string, std::less<>> ParseQuery(std::string_view target) {
  std::map<std::string, std::string, std::less<>> params;
  const size_t question = target.find('?');
  if (question == std::string_view::npos) return params;
  std::string_view rest = target.substr(question + 1);
  while (!rest.empty()) {
    const size_t amp = rest.find('&');
    const std::string_view pair = rest.substr(0, amp);
    rest = amp == std::string_view::npos ? std::string_view() : rest.substr(amp + 1);
    if (pair.empty()) continue;
    const size_t eq = pair.find('=');
    std::string name = DecodeQueryComponent(pair.substr(0, eq));
    std::string value =
        eq == std::string_view::npos ? "" : DecodeQueryComponent(pair.substr(eq + 1));
    params.emplace(std::move(name), std::move(value));
  }
  return params;
}

}  // namespace tod::server::http
