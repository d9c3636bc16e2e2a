// The query string of a request target, percent-decoded ('+' is a space).
#pragma once

#include <map>
#include <string>
#include <string_view>

namespace tod::server::http {

// name -> value; a name given twice keeps its first value. "/p?a=1&b" gives {a: "1", b: ""}.
std::map<std::string, std::string, std::less<>> ParseQuery(std::string_view target);

}  // namespace tod::server::http
