#include "core/synth/synth_effects.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace tod::synth {

CameraEffects SampleCameraEffects(Rng& rng, double pixel_scale) {
  CameraEffects e;
  e.blur_sigma_px = rng.Uniform(0.3, 1.3) * std::max(0.35, pixel_scale);
  e.motion_blur_px = rng.Chance(0.15) ? rng.Uniform(2.0, 6.0) * pixel_scale : 0.0;
  e.exposure = static_cast<float>(rng.LogUniform(0.65, 1.35));
  e.white_balance = cv::Vec3f(static_cast<float>(rng.Uniform(0.92, 1.08)), 1.0f,
                              static_cast<float>(rng.Uniform(0.92, 1.08)));
  e.vignetting = static_cast<float>(rng.Uniform(0.0, 0.35));
  e.gamma = static_cast<float>(rng.Uniform(0.8, 1.2));
  e.noise_sigma = static_cast<float>(rng.Uniform(0.8, 5.0));
  e.noise_seed = rng.Bits();
  return e;
}

cv::Mat3b ApplyCameraEffects(const cv::Mat3f& scene, const CameraEffects& e) {
  cv::Mat3f img;
  if (e.blur_sigma_px > 0.2) {
    cv::GaussianBlur(scene, img, cv::Size(), e.blur_sigma_px);
  } else {
    img = scene.clone();
  }
  if (e.motion_blur_px >= 1.5) {
    const int len = static_cast<int>(std::lround(e.motion_blur_px)) | 1;
    const cv::Mat1f kernel = cv::Mat1f::ones(1, len) / static_cast<float>(len);
    cv::filter2D(img, img, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  }
  // Tone curve as a lookup on the 0..255 scale (the scene may exceed 255: it clips).
  constexpr int kLut = 1024;
  std::vector<float> tone(kLut + 1);
  for (int i = 0; i <= kLut; ++i) {
    tone[i] = 255.0f * std::pow(static_cast<float>(i) / kLut, e.gamma);
  }
  const float cx = 0.5f * img.cols, cy = 0.5f * img.rows;
  const float inv_r2 = 1.0f / (cx * cx + cy * cy);
  std::uint64_t state = MixSeed(e.noise_seed) | 1ULL;
  cv::Mat3b out(img.size());
  for (int y = 0; y < img.rows; ++y) {
    const cv::Vec3f* in = img.ptr<cv::Vec3f>(y);
    cv::Vec3b* o = out.ptr<cv::Vec3b>(y);
    const float dy2 = (y + 0.5f - cy) * (y + 0.5f - cy);
    for (int x = 0; x < img.cols; ++x) {
      const float dx = x + 0.5f - cx;
      const float gain = e.exposure * (1.0f - e.vignetting * (dx * dx + dy2) * inv_r2);
      // One xorshift64* draw per pixel: three 21-bit fields, each split into two uniforms whose
      // sum (triangular, variance 1/6) is scaled to unit variance: close enough to Gaussian.
      state ^= state >> 12;
      state ^= state << 25;
      state ^= state >> 27;
      const std::uint64_t r = state * 0x2545F4914F6CDD1DULL;
      for (int c = 0; c < 3; ++c) {
        const std::uint64_t field = r >> (21 * c);
        const float u =
            static_cast<float>((field & 0x3FF) + ((field >> 10) & 0x3FF)) * (1.0f / 1024.0f);
        const float gaussian = (u - 1.0f) * 2.4494897f;  // sqrt(6)
        const float linear = std::clamp(in[x][c] * e.white_balance[c] * gain / 255.0f, 0.0f, 1.0f);
        const float v = tone[static_cast<int>(linear * kLut)] + e.noise_sigma * gaussian;
        o[x][c] = static_cast<uchar>(std::clamp(v, 0.0f, 255.0f) + 0.5f);
      }
    }
  }
  return out;
}

}  // namespace tod::synth
