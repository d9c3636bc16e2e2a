// The names of the probability map kinds (detector.h), shared by REST, the CLI and the JSON.
#include "core/pipeline/detector.h"

namespace tod {

const char* MapKindName(MapKind kind) {
  switch (kind) {
    case MapKind::kNormalized:
      return "normalized";
    case MapKind::kCalibrated:
      return "calibrated";
  }
  return "normalized";
}

std::optional<MapKind> ParseMapKind(std::string_view name) {
  if (name == "normalized") return MapKind::kNormalized;
  if (name == "calibrated") return MapKind::kCalibrated;
  return std::nullopt;
}

}  // namespace tod
