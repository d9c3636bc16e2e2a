#include "core/calibration/horizon_choice.h"

#include <cmath>
#include <string>

namespace tod {

const char* HorizonSourceName(HorizonSource source) {
  switch (source) {
    case HorizonSource::kFrame:
      return "frame";
    case HorizonSource::kCamera:
      return "camera";
    case HorizonSource::kBundle:
      break;
  }
  return "bundle";
}

HorizonUse ChooseHorizon(std::optional<double> bundle_row, int frame_height,
                         const HorizonEstimate& frame, CameraTrack* camera,
                         const HorizonChoiceParams& params) {
  HorizonUse use;
  use.bundle_row = bundle_row;
  use.row = bundle_row;
  if (frame.found) use.frame_estimate = frame.row;
  if (!bundle_row) {
    use.fallback = "the bundle has no horizon reference (tod calibrate adds one)";
    return use;
  }
  std::optional<double> estimate = use.frame_estimate;
  if (camera != nullptr) {
    // The camera keeps rows as shares of the frame's height, so a camera that changes its frame
    // size (a rescaled stream) keeps its estimate.
    std::optional<double> share;
    if (use.frame_estimate) share = *use.frame_estimate / frame_height;
    const CameraTrack::View view = camera->Observe(share);
    if (view.row) {
      use.source = HorizonSource::kCamera;
      use.camera_frames = view.frames;
      estimate = *view.row * frame_height;
    }
  }
  if (!estimate) {
    use.fallback = frame.reason.empty() ? "no horizon estimate" : frame.reason;
    return use;
  }
  const double rows_per_1024 = frame_height / 1024.0;
  double deadband = params.deadband_rows_at_1024 * rows_per_1024;
  if (use.source != HorizonSource::kCamera) {
    if (frame.peak_pairs < params.frame_min_peak_pairs) {
      use.fallback = "a lone frame's estimate from " + std::to_string(frame.peak_pairs) +
                     " agreeing pairs is too weak to move the geometry (" +
                     std::to_string(params.frame_min_peak_pairs) +
                     " needed; a camera_id accumulates one over its frames)";
      return use;
    }
    use.source = HorizonSource::kFrame;
    deadband = params.frame_deadband_rows_at_1024 * rows_per_1024;
  }
  use.row = estimate;
  if (std::abs(*estimate - *bundle_row) > deadband) use.shift = *estimate - *bundle_row;
  return use;
}

}  // namespace tod
