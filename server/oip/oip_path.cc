#include "server/oip/oip_path.h"

#include <vector>

namespace tod::server::oip {
namespace {

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// "%41b" -> "Ab"; nullopt for a truncated or non-hex escape. '+' stays '+' (paths are not forms).
std::optional<std::string> PercentDecode(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out += text[i];
      continue;
    }
    if (i + 2 >= text.size()) return std::nullopt;
    const int high = HexValue(text[i + 1]);
    const int low = HexValue(text[i + 2]);
    if (high < 0 || low < 0) return std::nullopt;
    out += static_cast<char>(high * 16 + low);
    i += 2;
  }
  return out;
}

}  // namespace

std::optional<ModelPath> ParseModelPath(std::string_view path) {
  if (!path.starts_with(kModelsPrefix)) return std::nullopt;
  std::string_view rest = path.substr(kModelsPrefix.size());
  // At most four segments: name, "versions", version, action; a fifth means no such path.
  std::vector<std::string> segments;
  while (segments.size() < 5) {
    const size_t slash = rest.find('/');
    const std::optional<std::string> segment = PercentDecode(rest.substr(0, slash));
    if (!segment || segment->empty()) return std::nullopt;
    segments.push_back(*segment);
    if (slash == std::string_view::npos) break;
    rest.remove_prefix(slash + 1);
  }
  ModelPath parsed;
  parsed.name = segments[0];
  size_t next = 1;
  if (segments.size() >= 3 && segments[1] == "versions") {
    parsed.version = segments[2];
    next = 3;
  }
  if (next == segments.size()) return parsed;  // metadata
  if (next + 1 != segments.size()) return std::nullopt;
  if (segments[next] == "ready") {
    parsed.action = ModelAction::kReady;
  } else if (segments[next] == "infer") {
    parsed.action = ModelAction::kInfer;
  } else {
    return std::nullopt;
  }
  return parsed;
}

}  // namespace tod::server::oip
