#include "core/edges/edge_channels.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/core/hal/hal.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/base/row_bands.h"

namespace tod {

// In bands of rows on OpenCV's pool: the conversion, cv::cvtColor (which splits large images
// itself but not the conversion to float or the scaling) and the scaling are per pixel, so the
// bands give the pixels of one call over the whole image.
cv::Mat3f BgrToLuv(const cv::Mat3b& bgr) {
  if (bgr.empty()) return {};
  cv::Mat3f luv(bgr.size());
  ForEachRowBand(bgr.rows, [&](const cv::Range& rows) {
    cv::Mat3f bgr_unit;
    bgr.rowRange(rows).convertTo(bgr_unit, CV_32F, 1.0 / 255.0);
    cv::Mat band = luv.rowRange(rows);
    // Float input gives L in [0,100] and u, v in roughly [-134,220]; one common scale keeps the
    // channels comparable.
    cv::cvtColor(bgr_unit, band, cv::COLOR_BGR2Luv);
    band *= 0.01f;
  });
  return luv;
}

// Bands of rows on OpenCV's pool, each pixel that of one filter call over the whole image
// (row_bands.h).
cv::Mat TriangleSmooth(const cv::Mat& src, int radius) {
  if (radius <= 0 || src.empty()) return src.clone();
  const int taps = 2 * radius + 1;
  cv::Mat1f kernel(1, taps);
  const float norm = 1.f / static_cast<float>((radius + 1) * (radius + 1));
  for (int i = 0; i < taps; ++i) {
    kernel(0, i) = static_cast<float>(radius + 1 - std::abs(i - radius)) * norm;
  }
  return SepFilterInRowBands(src, kernel, kernel);
}

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Central differences of the channel with the largest squared gradient, for one row. Ties go to
// the earlier channel. Written branch-free so the interior loop vectorises.
void WinningGradientRow(const float* up, const float* row, const float* down, int cols,
                        float* best_dx, float* best_dy) {
  const auto pixel = [&](int x, int left, int right) {
    float dx = 0.5f * (row[3 * right] - row[3 * left]);
    float dy = 0.5f * (down[3 * x] - up[3 * x]);
    float best_sq = dx * dx + dy * dy;
    for (int c = 1; c < 3; ++c) {
      const float cdx = 0.5f * (row[3 * right + c] - row[3 * left + c]);
      const float cdy = 0.5f * (down[3 * x + c] - up[3 * x + c]);
      const float sq = cdx * cdx + cdy * cdy;
      const bool wins = sq > best_sq;
      dx = wins ? cdx : dx;
      dy = wins ? cdy : dy;
      best_sq = wins ? sq : best_sq;
    }
    best_dx[x] = dx;
    best_dy[x] = dy;
  };
  pixel(0, 0, std::min(1, cols - 1));  // replicated border
  for (int x = 1; x < cols - 1; ++x) pixel(x, x - 1, x + 1);
  if (cols > 1) pixel(cols - 1, cols - 2, cols - 1);
}

// Runs `per_row(y, dx, dy, scratch)` with the winning differences of every row of `luv` and a
// scratch row of luv.cols floats. Rows only read `luv` and write their own outputs, so they run in
// bands on OpenCV's pool (as wide as the request's threads) with the same values for any width.
// Bands, not OpenCV's default split: that gave every row a stripe of its own, whose three scratch
// rows took the shared heap's lock three times a row while the other thread did the same.
template <typename PerRow>
void ForEachGradientRow(const cv::Mat3f& luv, const PerRow& per_row) {
  ForEachRowBand(luv.rows, [&](const cv::Range& rows) {
    std::vector<float> dx(static_cast<std::size_t>(luv.cols));
    std::vector<float> dy(static_cast<std::size_t>(luv.cols));
    std::vector<float> scratch(static_cast<std::size_t>(luv.cols));
    for (int y = rows.start; y < rows.end; ++y) {
      WinningGradientRow(luv.ptr<float>(std::max(y - 1, 0)), luv.ptr<float>(y),
                         luv.ptr<float>(std::min(y + 1, luv.rows - 1)), luv.cols, dx.data(),
                         dy.data());
      per_row(y, dx.data(), dy.data(), scratch.data());
    }
  });
}

// Adds magnitude m with doubled-angle cosine / sine (c, s) to the 4 bins (see the header).
inline void AddToBins(float m, float c, float s, float* const* bins, int x) {
  const float weight = m / std::max(std::abs(c) + std::abs(s), 1e-12f);
  bins[0][x] = weight * std::max(c, 0.f);
  bins[1][x] = weight * std::max(s, 0.f);
  bins[2][x] = weight * std::max(-c, 0.f);
  bins[3][x] = weight * std::max(-s, 0.f);
}

}  // namespace

ColourGradient ComputeColourGradient(const cv::Mat3f& luv, bool with_orientation) {
  ColourGradient result;
  if (luv.empty()) return result;
  result.magnitude.create(luv.size());
  if (with_orientation) result.orientation.create(luv.size());
  ForEachGradientRow(luv, [&](int y, const float* dx, const float* dy, float*) {
    float* magnitude = result.magnitude.ptr<float>(y);
    for (int x = 0; x < luv.cols; ++x) magnitude[x] = std::sqrt(dx[x] * dx[x] + dy[x] * dy[x]);
    if (!with_orientation) return;
    float* orientation = result.orientation.ptr<float>(y);
    for (int x = 0; x < luv.cols; ++x) {
      float angle = std::atan2(dy[x], dx[x]);  // (-pi, pi]
      if (angle < 0.f) angle += kPi;
      orientation[x] = angle >= kPi ? 0.f : angle;
    }
  });
  return result;
}

std::array<cv::Mat1f, kOrientationBins> OrientationHistograms(const ColourGradient& gradient) {
  std::array<cv::Mat1f, kOrientationBins> bins;
  const cv::Mat1f& magnitude = gradient.magnitude;
  for (cv::Mat1f& bin : bins) bin = cv::Mat1f::zeros(magnitude.size());
  if (magnitude.empty() || gradient.orientation.size() != magnitude.size()) return bins;
  for (int y = 0; y < magnitude.rows; ++y) {
    const float* m = magnitude.ptr<float>(y);
    const float* o = gradient.orientation.ptr<float>(y);
    float* out[kOrientationBins] = {bins[0].ptr<float>(y), bins[1].ptr<float>(y),
                                    bins[2].ptr<float>(y), bins[3].ptr<float>(y)};
    for (int x = 0; x < magnitude.cols; ++x) {
      AddToBins(m[x], std::cos(2.f * o[x]), std::sin(2.f * o[x]), out, x);
    }
  }
  return bins;
}

namespace {

cv::Mat1f Halve(const cv::Mat1f& full) {
  cv::Mat1f half;
  cv::resize(full, half, cv::Size(full.cols / 2, full.rows / 2), 0, 0, cv::INTER_AREA);
  return half;
}

// Magnitude and the 4 oriented bins of one row from the winning differences; sq is scratch.
// Written so that the loops vectorise (~3x faster than the plain loop). std::sqrt may set errno,
// which keeps the compiler from vectorising it, so the square roots go through
// cv::hal::sqrt32f (SIMD square roots, correctly rounded like std::sqrt). "sq > 0 ? 1 / sq : 0"
// becomes branch-free arithmetic on p = (sq > 0): 1 / (sq + (1 - p)) · p divides by sq itself
// where sq > 0 and by 1 (then times 0) where sq == 0, so every value is the one the conditional
// gave. The bins are AddToBins spelled out (same expressions, same order).
void GradientRowChannels(const float* __restrict dx, const float* __restrict dy, int cols,
                         float* __restrict sq, float* __restrict magnitude, float* __restrict bin0,
                         float* __restrict bin1, float* __restrict bin2, float* __restrict bin3) {
  for (int x = 0; x < cols; ++x) sq[x] = dx[x] * dx[x] + dy[x] * dy[x];
  cv::hal::sqrt32f(sq, magnitude, cols);
  for (int x = 0; x < cols; ++x) {
    const float p = static_cast<float>(sq[x] > 0.f);
    const float inv_sq = 1.f / (sq[x] + (1.f - p)) * p;
    const float c = (dx[x] * dx[x] - dy[x] * dy[x]) * inv_sq;
    const float s = 2.f * dx[x] * dy[x] * inv_sq;
    const float weight = magnitude[x] / std::max(std::abs(c) + std::abs(s), 1e-12f);
    bin0[x] = weight * std::max(c, 0.f);
    bin1[x] = weight * std::max(s, 0.f);
    bin2[x] = weight * std::max(-c, 0.f);
    bin3[x] = weight * std::max(-s, 0.f);
  }
}

// Magnitude plus oriented histograms of one scale, in `planes` from index `first`. The bins come
// straight from the winning (dx, dy): cos 2theta = (dx^2 - dy^2) / m^2, sin 2theta = 2 dx dy / m^2.
void AddGradientChannels(const cv::Mat3f& luv, bool halve, std::vector<cv::Mat1f>& planes,
                         int first) {
  cv::Mat1f magnitude(luv.size());
  std::array<cv::Mat1f, kOrientationBins> bins;
  for (cv::Mat1f& bin : bins) bin.create(luv.size());
  ForEachGradientRow(luv, [&](int y, const float* dx, const float* dy, float* squared) {
    GradientRowChannels(dx, dy, luv.cols, squared, magnitude.ptr<float>(y), bins[0].ptr<float>(y),
                        bins[1].ptr<float>(y), bins[2].ptr<float>(y), bins[3].ptr<float>(y));
  });
  planes[first] = halve ? Halve(magnitude) : magnitude;
  for (int b = 0; b < kOrientationBins; ++b) {
    planes[first + 1 + b] = halve ? Halve(bins[b]) : bins[b];
  }
}

}  // namespace

EdgeChannels ComputeEdgeChannels(const cv::Mat3b& bgr, const EdgeChannelParams& params) {
  EdgeChannels channels;
  if (bgr.empty()) return channels;
  // Pad to even size so that the half-resolution grid is an exact 2x2 pooling.
  cv::Mat3b padded;
  cv::copyMakeBorder(bgr, padded, 0, bgr.rows % 2, 0, bgr.cols % 2, cv::BORDER_REPLICATE);
  const cv::Mat3f luv_full = TriangleSmooth(BgrToLuv(padded), params.image_smooth_radius);
  cv::Mat3f luv_half;
  cv::resize(luv_full, luv_half, cv::Size(padded.cols / 2, padded.rows / 2), 0, 0, cv::INTER_AREA);

  channels.planes.resize(kNumEdgeChannels);
  std::vector<cv::Mat1f> colour(3);
  cv::split(luv_half, colour);
  for (int c = 0; c < 3; ++c) channels.planes[kChanL + c] = colour[c];
  AddGradientChannels(luv_full, /*halve=*/true, channels.planes, kChanGradFull);
  AddGradientChannels(luv_half, /*halve=*/false, channels.planes, kChanGradHalf);
  for (cv::Mat1f& plane : channels.planes) {
    plane = TriangleSmooth(plane, params.channel_smooth_radius);
  }
  return channels;
}

}  // namespace tod
