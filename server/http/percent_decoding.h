// Percent-decoding (RFC 3986) of request targets, in the two forms the server needs: a query
// component (forgiving, as browsers send them) and a path segment (strict: a path that names a
// resource must mean exactly one thing).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace tod::server::http {

// "a+b%2C" -> "a b,"; a '%' not followed by two hex digits is kept as it is.
std::string DecodeQueryComponent(std::string_view text);

// "%41b" -> "Ab"; nullopt for a truncated or non-hex escape. '+' stays '+' (paths are not forms).
std::optional<std::string> DecodePathSegment(std::string_view text);

}  // namespace tod::server::http
