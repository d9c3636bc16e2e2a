#include "server/oip/oip_path.h"

#include <vector>

#include "server/http/percent_decoding.h"

namespace tod::server::oip {

std::optional<ModelPath> ParseModelPath(std::string_view path) {
  if (!path.starts_with(kModelsPrefix)) return std::nullopt;
  std::string_view rest = path.substr(kModelsPrefix.size());
  // At most four segments: name, "versions", version, action; a fifth means no such path.
  std::vector<std::string> segments;
  while (segments.size() < 5) {
    const size_t slash = rest.find('/');
    const std::optional<std::string> segment = http::DecodePathSegment(rest.substr(0, slash));
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
