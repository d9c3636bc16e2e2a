#include "core/cli/eval_geometry_option.h"

#include <string>

namespace tod::cli {

void AddEvalGeometryOption(CLI::App* cmd, EvalGeometry* geometry) {
  cmd->add_option_function<std::string>(
         "--geometry",
         [geometry](const std::string& name) { *geometry = *ParseEvalGeometry(name); },
         "road geometry: frame (each frame calibrated alone, as a request without camera_id), "
         "camera (the split is one camera: its median horizon over the split), bundle (no "
         "calibration); default frame")
      ->check(CLI::IsMember({EvalGeometryName(EvalGeometry::kFrame),
                             EvalGeometryName(EvalGeometry::kCamera),
                             EvalGeometryName(EvalGeometry::kBundle)}));
}

}  // namespace tod::cli
