#include "core/synth/synth_canvas.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tod::synth {
namespace {

// fillPoly works on integer points; 4 fractional bits keep sub-pixel shapes (far, tiny
// obstacles) faithful. Coordinates are clamped so far off-screen vertices cannot overflow.
constexpr int kShiftBits = 4;
constexpr double kShiftScale = 1 << kShiftBits;

cv::Point ToFixed(const cv::Point2d& p) {
  constexpr double kLimit = 1e6;
  return {static_cast<int>(std::lround(std::clamp(p.x, -kLimit, kLimit) * kShiftScale)),
          static_cast<int>(std::lround(std::clamp(p.y, -kLimit, kLimit) * kShiftScale))};
}

}  // namespace

Canvas::Canvas(cv::Size size)
    : colour(size, cv::Vec3f(0, 0, 0)),
      instance_ids(cv::Mat1w::zeros(size)),
      label_ids(cv::Mat1b::zeros(size)),
      surface(cv::Mat1b::zeros(size)),
      detail(cv::Mat1f::zeros(size)) {}

Region RasterisePolygons(const std::vector<std::vector<cv::Point2d>>& polygons, cv::Size frame) {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const auto& poly : polygons) {
    for (const cv::Point2d& p : poly) {
      x0 = std::min(x0, p.x);
      y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
    }
  }
  Region region;
  if (x1 < x0) return region;
  const cv::Rect bounds(
      cv::Point(static_cast<int>(std::floor(std::max(x0, -1.0))),
                static_cast<int>(std::floor(std::max(y0, -1.0)))),
      cv::Point(static_cast<int>(std::ceil(std::min(x1, frame.width + 1.0))) + 1,
                static_cast<int>(std::ceil(std::min(y1, frame.height + 1.0))) + 1));
  region.roi = bounds & cv::Rect(0, 0, frame.width, frame.height);
  if (region.roi.area() == 0) return region;
  region.mask = cv::Mat1b::zeros(region.roi.size());
  std::vector<std::vector<cv::Point>> fixed;
  fixed.reserve(polygons.size());
  // Our image coordinates put pixel i on [i, i + 1); fillPoly puts pixel centres on integers.
  const cv::Point2d origin(region.roi.x + 0.5, region.roi.y + 0.5);
  for (const auto& poly : polygons) {
    if (poly.size() < 3) continue;
    std::vector<cv::Point> pts;
    pts.reserve(poly.size());
    for (const cv::Point2d& p : poly) pts.push_back(ToFixed(p - origin));
    fixed.push_back(std::move(pts));
  }
  // One call per polygon: a single fillPoly over several polygons uses the even-odd rule, which
  // would cut holes where they overlap; we want their union.
  for (const std::vector<cv::Point>& pts : fixed) {
    cv::fillPoly(region.mask, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(255), cv::LINE_8,
                 kShiftBits);
  }
  return region;
}

Region RasteriseEllipse(cv::Point2d centre, cv::Size2d semi_axes, double angle_deg,
                        cv::Size frame) {
  // As a polygon so it shares the sub-pixel rasterisation of everything else.
  constexpr int kSegments = 48;
  const double a = angle_deg * CV_PI / 180.0;
  const double ca = std::cos(a), sa = std::sin(a);
  std::vector<cv::Point2d> poly;
  poly.reserve(kSegments);
  for (int i = 0; i < kSegments; ++i) {
    const double t = 2.0 * CV_PI * i / kSegments;
    const double ex = semi_axes.width * std::cos(t), ey = semi_axes.height * std::sin(t);
    poly.emplace_back(centre.x + ca * ex - sa * ey, centre.y + sa * ex + ca * ey);
  }
  return RasterisePolygons({poly}, frame);
}

void RestrictToSurface(const Canvas& canvas, Region& region, Surface keep) {
  if (region.empty()) return;
  const cv::Mat1b surface = canvas.surface(region.roi);
  for (int y = 0; y < region.roi.height; ++y) {
    uchar* m = region.mask.ptr<uchar>(y);
    const uchar* s = surface.ptr<uchar>(y);
    for (int x = 0; x < region.roi.width; ++x) {
      if (s[x] != static_cast<uchar>(keep)) m[x] = 0;
    }
  }
}

void Paint(Canvas& canvas, const Region& region, const cv::Vec3f& colour, float texture_amp,
           std::optional<Labels> labels, std::optional<Surface> surface) {
  if (region.empty()) return;
  for (int y = 0; y < region.roi.height; ++y) {
    const int fy = region.roi.y + y;
    const uchar* m = region.mask.ptr<uchar>(y);
    cv::Vec3f* c = canvas.colour.ptr<cv::Vec3f>(fy) + region.roi.x;
    const float* d = canvas.detail.ptr<float>(fy) + region.roi.x;
    ushort* inst = canvas.instance_ids.ptr<ushort>(fy) + region.roi.x;
    uchar* lab = canvas.label_ids.ptr<uchar>(fy) + region.roi.x;
    uchar* surf = canvas.surface.ptr<uchar>(fy) + region.roi.x;
    for (int x = 0; x < region.roi.width; ++x) {
      if (!m[x]) continue;
      c[x] = colour * (1.0f + texture_amp * d[x]);
      if (labels) {
        inst[x] = labels->instance_id;
        lab[x] = labels->label_id;
      }
      if (surface) surf[x] = static_cast<uchar>(*surface);
    }
  }
}

void Blend(Canvas& canvas, const Region& region, const cv::Vec3f& colour, float alpha,
           float texture_amp) {
  if (region.empty()) return;
  for (int y = 0; y < region.roi.height; ++y) {
    const int fy = region.roi.y + y;
    const uchar* m = region.mask.ptr<uchar>(y);
    cv::Vec3f* c = canvas.colour.ptr<cv::Vec3f>(fy) + region.roi.x;
    const float* d = canvas.detail.ptr<float>(fy) + region.roi.x;
    for (int x = 0; x < region.roi.width; ++x) {
      if (!m[x]) continue;
      const float a = std::clamp(alpha * (1.0f + texture_amp * d[x]), 0.0f, 1.0f);
      c[x] = c[x] * (1.0f - a) + colour * a;
    }
  }
}

void Darken(Canvas& canvas, const Region& region, float strength, double soft_px) {
  if (region.empty()) return;
  // Grow the ROI so the softened edge has room, then blur the mask into a penumbra.
  const int pad = static_cast<int>(std::ceil(3.0 * soft_px)) + 1;
  const cv::Rect grown = cv::Rect(region.roi.x - pad, region.roi.y - pad,
                                  region.roi.width + 2 * pad, region.roi.height + 2 * pad) &
                         cv::Rect(cv::Point(0, 0), canvas.size());
  cv::Mat1f soft = cv::Mat1f::zeros(grown.size());
  cv::Mat1f(region.mask / 255.0f)
      .copyTo(soft(cv::Rect(region.roi.x - grown.x, region.roi.y - grown.y, region.roi.width,
                            region.roi.height)));
  if (soft_px > 4.0) {
    // Three box blurs approximate a Gaussian at a cost independent of its width.
    const int box = std::max(3, static_cast<int>(std::lround(soft_px * 2.0)) | 1);
    for (int pass = 0; pass < 3; ++pass) cv::blur(soft, soft, cv::Size(box, box));
  } else if (soft_px > 0.3) {
    cv::GaussianBlur(soft, soft, cv::Size(), soft_px);
  }
  for (int y = 0; y < grown.height; ++y) {
    const int fy = grown.y + y;
    const float* s = soft.ptr<float>(y);
    cv::Vec3f* c = canvas.colour.ptr<cv::Vec3f>(fy) + grown.x;
    const uchar* surf = canvas.surface.ptr<uchar>(fy) + grown.x;
    for (int x = 0; x < grown.width; ++x) {
      if (s[x] <= 0.0f || !IsGround(static_cast<Surface>(surf[x]))) continue;
      c[x] *= 1.0f - strength * s[x];
    }
  }
}

cv::Mat1f FractalNoise(cv::Size size, double coarsest_px, int octaves, Rng& rng) {
  // Built coarse to fine: upsample the running sum by two and add a new random lattice, so only
  // the final upsampling touches every pixel (one cubic resize instead of one per octave).
  auto random_grid = [&rng](int rows, int cols) {
    cv::Mat1f grid(rows, cols);
    for (int y = 0; y < rows; ++y) {
      for (int x = 0; x < cols; ++x) grid(y, x) = static_cast<float>(rng.Uniform(-1.0, 1.0));
    }
    return grid;
  };
  double feature_px = std::max(1.0, coarsest_px);
  cv::Mat1f sum =
      random_grid(std::max(2, static_cast<int>(std::ceil(size.height / feature_px)) + 1),
                  std::max(2, static_cast<int>(std::ceil(size.width / feature_px)) + 1));
  double amplitude = 1.0, total = 1.0;
  for (int o = 1; o < octaves && feature_px >= 2.0; ++o) {
    feature_px *= 0.5;
    amplitude *= 0.55;
    cv::Mat1f up;
    cv::resize(sum, up, cv::Size(sum.cols * 2 - 1, sum.rows * 2 - 1), 0, 0, cv::INTER_LINEAR);
    sum = up + random_grid(up.rows, up.cols) * amplitude;
    total += amplitude;
  }
  cv::Mat1f out;
  cv::resize(sum, out, size, 0, 0, cv::INTER_CUBIC);
  out *= 1.0 / total;
  return out;
}

}  // namespace tod::synth
