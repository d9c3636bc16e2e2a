// The training camera's horizon as the estimator sees it (EstimateHorizon over the bundle's
// training frames): the row other cameras' horizons are shifted against. Measured with the same
// estimator, so whatever bias it has on road scenes cancels in the shift.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "core/base/status.h"
#include "core/calibration/horizon_estimator.h"

namespace tod {

struct HorizonReference {
  double row = 0;        // median estimate, training-frame rows
  double spread = 0;     // median absolute deviation of the estimates from it, rows
  int frames = 0;        // frames with an estimate
  int frame_height = 0;  // the training frames' height

  nlohmann::json ToJson() const;
  static Result<HorizonReference> FromJson(const nlohmann::json& j);
};

// The reference from the training frames' estimates (those not found are skipped); an error
// when fewer than min_frames have one.
Result<HorizonReference> ReferenceFromEstimates(const std::vector<HorizonEstimate>& estimates,
                                                int frame_height, int min_frames = 5);

}  // namespace tod
