// Which horizon a frame's geometry is placed at: the camera's (its median over the frames it
// sent), else this frame's own estimate, else the bundle's, and why (issue 48).
#pragma once

#include <optional>
#include <string>

#include "core/calibration/camera_registry.h"
#include "core/calibration/horizon_estimator.h"

namespace tod {

enum class HorizonSource { kBundle, kFrame, kCamera };
// "bundle" / "frame" / "camera", as the JSON and the metrics name them.
const char* HorizonSourceName(HorizonSource source);

struct HorizonUse {
  HorizonSource source = HorizonSource::kBundle;
  // The horizon the geometry stands on, frame rows: the estimate used, or the bundle's
  // reference mapped onto the frame; none for a bundle without a reference.
  std::optional<double> row;
  std::optional<double> bundle_row;      // the bundle's reference on this frame
  std::optional<double> frame_estimate;  // this frame's own estimate
  long long camera_frames = 0;           // frames behind the camera's estimate
  // Rows the bundle's regions, size filter and ground-plane features were moved down (up when
  // negative). 0 within the deadband: the training camera's own frames vary by that much.
  double shift = 0;
  std::string fallback;  // why the bundle's geometry was used (empty otherwise)
};

struct HorizonChoiceParams {
  // An estimate this close to the bundle's reference leaves the geometry where it is, in rows
  // at a height of 1024 (the Lost and Found camera's own frames spread by a median 15 rows).
  double deadband_rows_at_1024 = 24;
  // A lone frame (no camera) moves the geometry only when its own estimate is this far off the
  // reference and that many pairs agree on it: one frame's estimate on the Lost and Found
  // camera's own frames spreads by a median 10.7 rows (about 16 rows sigma: 3 sigma is 48), and
  // its two estimates 87-90 rows off came from 21 and 23 pairs. Moved by the camera's deadband,
  // 10 of its 100 frames were moved, and the 5-fold CV lost pixel AP on every fold
  // (docs/findings.md, self-calibration).
  double frame_deadband_rows_at_1024 = 48;
  int frame_min_peak_pairs = 40;
};

// bundle_row: the bundle's reference mapped onto this frame (none: the bundle has no reference,
// and the geometry stays the bundle's). camera: the camera's track, or null for a lone frame.
HorizonUse ChooseHorizon(std::optional<double> bundle_row, int frame_height,
                         const HorizonEstimate& frame, CameraTrack* camera,
                         const HorizonChoiceParams& params = {});

}  // namespace tod
