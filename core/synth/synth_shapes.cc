#include "core/synth/synth_shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tod::synth {
namespace {

// Nothing is projected closer than this, so off-screen vertices stay finite.
constexpr double kMinDepthM = 0.3;

cv::Point2d ProjectClamped(const PinholeCamera& camera, double x, double y, double z) {
  return camera.Project(x, y, std::max(z, kMinDepthM));
}

}  // namespace

std::vector<cv::Point2d> Footprint(const Solid& box) {
  const double c = std::cos(box.yaw), s = std::sin(box.yaw);
  const double hw = 0.5 * box.width, hd = 0.5 * box.depth;
  std::vector<cv::Point2d> pts;
  for (const auto& [a, b] :
       std::array<std::pair<double, double>, 4>{{{-hw, -hd}, {hw, -hd}, {hw, hd}, {-hw, hd}}}) {
    pts.emplace_back(box.x + c * a + s * b, box.z - s * a + c * b);
  }
  return pts;
}

std::vector<ShadedPolygon> VisibleBoxFaces(const PinholeCamera& camera, const Solid& box,
                                           const Lighting& light) {
  const std::vector<cv::Point2d> foot = Footprint(box);
  const double y0 = box.base_y, y1 = box.base_y + box.height;
  const cv::Vec3d eye(0.0, camera.height_m, 0.0);
  std::vector<ShadedPolygon> faces;
  // Four sides: footprint edge i -> i + 1, outward normal in the ground plane.
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d a = foot[i], b = foot[(i + 1) % 4];
    const cv::Point2d mid = 0.5 * (a + b);
    const cv::Point2d centre(box.x, box.z);
    cv::Vec3d n(mid.x - centre.x, 0.0, mid.y - centre.y);
    const double len = cv::norm(n);
    if (len <= 0) continue;
    n /= len;
    const cv::Vec3d face_centre(mid.x, 0.5 * (y0 + y1), mid.y);
    if (n.dot(eye - face_centre) <= 0) continue;  // faces away from the camera
    faces.push_back({{ProjectClamped(camera, a.x, y0, a.y), ProjectClamped(camera, b.x, y0, b.y),
                      ProjectClamped(camera, b.x, y1, b.y), ProjectClamped(camera, a.x, y1, a.y)},
                     light.Shade(n)});
  }
  if (y1 < camera.height_m) {  // the top is visible from a camera above it
    ShadedPolygon top;
    for (const cv::Point2d& p : foot) top.points.push_back(ProjectClamped(camera, p.x, y1, p.y));
    top.shade = light.Shade({0.0, 1.0, 0.0});
    faces.push_back(std::move(top));
  }
  return faces;
}

std::vector<cv::Point2d> ProjectGroundPolygon(const PinholeCamera& camera,
                                              const std::vector<cv::Point2d>& xz, double y) {
  std::vector<cv::Point2d> out;
  out.reserve(xz.size());
  for (const cv::Point2d& p : xz) out.push_back(ProjectClamped(camera, p.x, y, p.y));
  return out;
}

std::vector<cv::Point2d> GroundEllipse(const PinholeCamera& camera, double cx, double cz, double rx,
                                       double rz, double angle, double y) {
  constexpr int kSegments = 32;
  const double c = std::cos(angle), s = std::sin(angle);
  std::vector<cv::Point2d> xz;
  xz.reserve(kSegments);
  for (int i = 0; i < kSegments; ++i) {
    const double t = 2.0 * CV_PI * i / kSegments;
    const double a = rx * std::cos(t), b = rz * std::sin(t);
    xz.emplace_back(cx + c * a - s * b, cz + s * a + c * b);
  }
  return ProjectGroundPolygon(camera, xz, y);
}

std::vector<std::vector<cv::Point2d>> GroundStroke(const PinholeCamera& camera,
                                                   const std::vector<cv::Point2d>& xz,
                                                   double width_m) {
  std::vector<std::vector<cv::Point2d>> quads;
  for (std::size_t i = 0; i + 1 < xz.size(); ++i) {
    const cv::Point2d d = xz[i + 1] - xz[i];
    const double len = cv::norm(d);
    if (len <= 1e-9) continue;
    const cv::Point2d n(-d.y / len * 0.5 * width_m, d.x / len * 0.5 * width_m);
    // Extend each segment by half a width so consecutive quads overlap at the joints.
    const cv::Point2d e = d * (0.5 * width_m / len);
    quads.push_back(ProjectGroundPolygon(
        camera, {xz[i] - e + n, xz[i + 1] + e + n, xz[i + 1] + e - n, xz[i] - e - n}));
  }
  return quads;
}

std::vector<cv::Point2d> CastShadow(const PinholeCamera& camera,
                                    const std::vector<cv::Point2d>& footprint_xz, double height,
                                    const Lighting& light) {
  const double elevation_sin = std::clamp(light.to_sun[1], 0.15, 1.0);
  const double horizontal = std::sqrt(std::max(1e-9, 1.0 - elevation_sin * elevation_sin));
  const double length = height * horizontal / elevation_sin;
  const cv::Point2d away(-light.to_sun[0], -light.to_sun[2]);
  const double n = std::max(1e-9, cv::norm(away));
  const cv::Point2d shift = away * (length / n);
  std::vector<cv::Point2f> image_pts;
  for (const cv::Point2d& p : footprint_xz) {
    for (const cv::Point2d& q : {p, p + shift}) {
      const cv::Point2d ip = ProjectClamped(camera, q.x, 0.0, q.y);
      image_pts.emplace_back(static_cast<float>(ip.x), static_cast<float>(ip.y));
    }
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(image_pts, hull);
  std::vector<cv::Point2d> out(hull.begin(), hull.end());
  return out;
}

}  // namespace tod::synth
