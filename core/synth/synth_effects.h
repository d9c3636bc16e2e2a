// The camera between the scene and the 8-bit image: optics blur (sometimes motion blur),
// exposure and white balance, vignetting, a tone curve, and sensor noise.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "core/synth/synth_rng.h"

namespace tod::synth {

struct CameraEffects {
  double blur_sigma_px = 0.6;
  double motion_blur_px = 0.0;  // horizontal streak length, 0 = none
  float exposure = 1.0f;
  cv::Vec3f white_balance{1, 1, 1};
  float vignetting = 0.15f;  // brightness lost in the corners
  float gamma = 1.0f;
  float noise_sigma = 2.0f;  // in 8-bit levels
  std::uint64_t noise_seed = 0;
};

// `pixel_scale` = image width / 2048, so blur follows resolution.
CameraEffects SampleCameraEffects(Rng& rng, double pixel_scale);

cv::Mat3b ApplyCameraEffects(const cv::Mat3f& scene, const CameraEffects& effects);

}  // namespace tod::synth
