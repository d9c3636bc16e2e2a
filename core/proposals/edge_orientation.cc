#include "core/proposals/edge_orientation.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

// Triangle filter of radius 4 (§4.1), applied separably with symmetric ("reflect") padding,
// i.e. the border pixel is repeated: fedcba|abcdef.
cv::Mat1f TriangleSmooth(const cv::Mat1f& map) {
  cv::Mat1f kernel(1, 9);
  for (int i = 0; i < 9; ++i) kernel(0, i) = static_cast<float>(5 - std::abs(i - 4)) / 25.f;
  cv::Mat1f smoothed;
  cv::sepFilter2D(map, smoothed, CV_32F, kernel, kernel.t(), cv::Point(-1, -1), 0.0,
                  cv::BORDER_REFLECT);
  return smoothed;
}

float Sign(float v) { return v > 0.f ? 1.f : (v < 0.f ? -1.f : 0.f); }

// theta from the three second derivatives, shared by the dense and the per-pixel paths.
float ThetaOf(float oxx, float oxy, float oyy) {
  constexpr float kPi = std::numbers::pi_v<float>;
  float t = std::atan(oyy * Sign(-oxy) / (oxx + 1e-5f));
  t = std::fmod(t, kPi);  // MATLAB mod: result takes the sign of the divisor
  if (t < 0.f) t += kPi;
  if (t >= kPi) t -= kPi;
  return t;
}

// DerivativeX / DerivativeY of a map given as value(r, c), at one pixel: the same expressions
// with the same border rules, so the values are bit-identical to the dense maps'.
template <typename Value>
float DerivativeXAt(const Value& value, int w, int r, int c) {
  if (w < 2) return 0.f;
  if (c == 0) return value(r, 1) - value(r, 0);
  if (c == w - 1) return value(r, w - 1) - value(r, w - 2);
  return 0.5f * (value(r, c + 1) - value(r, c - 1));
}

template <typename Value>
float DerivativeYAt(const Value& value, int h, int r, int c) {
  if (h < 2) return 0.f;
  const int up = r == 0 ? 0 : r - 1;
  const int down = r == h - 1 ? h - 1 : r + 1;
  const float scale = (r == 0 || r == h - 1) ? 1.f : 0.5f;
  return scale * (value(down, c) - value(up, c));
}

}  // namespace

cv::Mat1f DerivativeX(const cv::Mat1f& map) {
  cv::Mat1f dx(map.size(), 0.f);
  const int w = map.cols;
  if (w < 2) return dx;
  for (int r = 0; r < map.rows; ++r) {
    const float* in = map[r];
    float* out = dx[r];
    out[0] = in[1] - in[0];
    for (int c = 1; c < w - 1; ++c) out[c] = 0.5f * (in[c + 1] - in[c - 1]);
    out[w - 1] = in[w - 1] - in[w - 2];
  }
  return dx;
}

cv::Mat1f DerivativeY(const cv::Mat1f& map) {
  cv::Mat1f dy(map.size(), 0.f);
  const int h = map.rows;
  if (h < 2) return dy;
  for (int r = 0; r < h; ++r) {
    const int up = r == 0 ? 0 : r - 1;
    const int down = r == h - 1 ? h - 1 : r + 1;
    const float scale = (r == 0 || r == h - 1) ? 1.f : 0.5f;
    const float* a = map[up];
    const float* b = map[down];
    float* out = dy[r];
    for (int c = 0; c < map.cols; ++c) out[c] = scale * (b[c] - a[c]);
  }
  return dy;
}

cv::Mat1f ComputeEdgeOrientation(const cv::Mat1f& edge_map) {
  return ComputeEdgeOrientation(edge_map, -std::numeric_limits<float>::infinity());
}

cv::Mat1f SmoothForOrientation(const cv::Mat1f& edge_map) { return TriangleSmooth(edge_map); }

float OrientationAt(const cv::Mat1f& smoothed, int r, int c) {
  const int w = smoothed.cols, h = smoothed.rows;
  const auto s = [&smoothed](int y, int x) { return smoothed(y, x); };
  const auto ox = [&](int y, int x) { return DerivativeXAt(s, w, y, x); };
  const auto oy = [&](int y, int x) { return DerivativeYAt(s, h, y, x); };
  return ThetaOf(DerivativeXAt(ox, w, r, c), DerivativeXAt(oy, w, r, c),
                 DerivativeYAt(oy, h, r, c));
}

cv::Mat1f ComputeEdgeOrientation(const cv::Mat1f& edge_map, float min_magnitude) {
  if (edge_map.empty()) return {};
  const cv::Mat1f smoothed = TriangleSmooth(edge_map);
  const cv::Mat1f ox = DerivativeX(smoothed);
  const cv::Mat1f oy = DerivativeY(smoothed);
  const cv::Mat1f oxx = DerivativeX(ox);
  const cv::Mat1f oxy = DerivativeX(oy);
  const cv::Mat1f oyy = DerivativeY(oy);
  cv::Mat1f theta(edge_map.size(), 0.f);
  for (int r = 0; r < edge_map.rows; ++r) {
    for (int c = 0; c < edge_map.cols; ++c) {
      if (!(edge_map(r, c) > min_magnitude)) continue;
      theta(r, c) = ThetaOf(oxx(r, c), oxy(r, c), oyy(r, c));
    }
  }
  return theta;
}

}  // namespace tod
