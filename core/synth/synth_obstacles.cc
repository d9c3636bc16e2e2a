#include "core/synth/synth_obstacles.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tod::synth {
namespace {

constexpr double kTwoPi = 2.0 * CV_PI;

// a &= !b, in a's frame.
void Subtract(Region& a, const Region& b) {
  const cv::Rect overlap = a.roi & b.roi;
  if (overlap.area() == 0) return;
  cv::Mat1b am = a.mask(overlap - a.roi.tl()), bm = b.mask(overlap - b.roi.tl());
  am.setTo(0, bm);
}
// a &= b, in a's frame.
void IntersectWith(Region& a, const Region& b) {
  cv::Mat1b keep = cv::Mat1b::zeros(a.mask.size());
  const cv::Rect overlap = a.roi & b.roi;
  if (overlap.area() > 0) b.mask(overlap - b.roi.tl()).copyTo(keep(overlap - a.roi.tl()));
  cv::bitwise_and(a.mask, keep, a.mask);
}

std::vector<cv::Point2d> Circle(double cx, double cz, double r, int segments = 24) {
  std::vector<cv::Point2d> pts;
  for (int i = 0; i < segments; ++i) {
    const double t = kTwoPi * i / segments;
    pts.emplace_back(cx + r * std::cos(t), cz + r * std::sin(t));
  }
  return pts;
}

std::vector<cv::Point2d> ConvexHull(const std::vector<cv::Point2d>& pts) {
  std::vector<cv::Point2f> in;
  for (const cv::Point2d& p : pts)
    in.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y));
  std::vector<cv::Point2f> hull;
  cv::convexHull(in, hull);
  return {hull.begin(), hull.end()};
}

// Multiplies the region's pixels by a factor rising from `bottom` at the lowest row to `top` at
// the highest: ambient occlusion near the ground, the "shading gradient" of the issue.
void VerticalGradient(Canvas& canvas, const Region& region, float bottom, float top) {
  if (region.empty()) return;
  const int h = region.roi.height;
  for (int y = 0; y < h; ++y) {
    const float t = h > 1 ? static_cast<float>(h - 1 - y) / (h - 1) : 1.0f;
    const float f = bottom + (top - bottom) * t;
    const uchar* m = region.mask.ptr<uchar>(y);
    cv::Vec3f* c = canvas.colour.ptr<cv::Vec3f>(region.roi.y + y) + region.roi.x;
    for (int x = 0; x < region.roi.width; ++x) {
      if (m[x]) c[x] *= f;
    }
  }
}

// Paints with a per-pixel shade computed from the pixel's position.
template <typename ShadeFn>
void PaintShaded(Canvas& canvas, const Region& region, const cv::Vec3f& colour, Labels labels,
                 ShadeFn shade_at) {
  if (region.empty()) return;
  for (int y = 0; y < region.roi.height; ++y) {
    const int fy = region.roi.y + y;
    const uchar* m = region.mask.ptr<uchar>(y);
    for (int x = 0; x < region.roi.width; ++x) {
      if (!m[x]) continue;
      const int fx = region.roi.x + x;
      canvas.colour(fy, fx) =
          colour * shade_at(fx + 0.5, fy + 0.5) * (1.0f + 0.04f * canvas.detail(fy, fx));
      canvas.instance_ids(fy, fx) = labels.instance_id;
      canvas.label_ids(fy, fx) = labels.label_id;
      canvas.surface(fy, fx) = static_cast<uchar>(Surface::kStanding);
    }
  }
}

void PaintFlat(Canvas& canvas, const Region& region, const cv::Vec3f& colour, Labels labels) {
  Paint(canvas, region, colour, 0.04f, labels, Surface::kStanding);
}

// Horizontal unit vector from the obstacle towards the camera, as an angle (X = sin, Z = cos).
double AzimuthToCamera(const SynthObstacleSpec& s) { return std::atan2(-s.x_m, -s.z_m); }

// Shade of a vertical round surface at image column u, given the silhouette's column span.
float RoundSideShade(const Lighting& light, double view_az, double u, double u0, double u1) {
  const double t = std::clamp(2.0 * (u - u0) / std::max(1e-6, u1 - u0) - 1.0, -0.999, 0.999);
  const double phi = view_az - std::asin(t);  // image right = world right of the view direction
  return light.Shade(cv::Vec3d(std::sin(phi), 0.0, std::cos(phi)));
}

Region DrawBox(Canvas& canvas, const SceneLayout& layout, const SynthObstacleSpec& s,
               Labels labels) {
  const Solid box{s.x_m, s.z_m, s.width_m, s.depth_m, s.height_m, s.yaw_rad, 0.0};
  std::vector<std::vector<cv::Point2d>> all;
  for (const ShadedPolygon& face : VisibleBoxFaces(layout.camera, box, layout.light)) {
    PaintFlat(canvas, RasterisePolygons({face.points}, canvas.size()), s.colour_bgr * face.shade,
              labels);
    all.push_back(face.points);
  }
  return RasterisePolygons(all, canvas.size());
}

// Vertical cylinder (also a lying tyre): round side shaded by column, flat lit top.
Region DrawCylinder(Canvas& canvas, const SceneLayout& layout, const SynthObstacleSpec& s,
                    Labels labels, bool tyre_hole) {
  const PinholeCamera& cam = layout.camera;
  const double r = 0.5 * s.width_m;
  std::vector<cv::Point2d> pts = ProjectGroundPolygon(cam, Circle(s.x_m, s.z_m, r), 0.0);
  const std::vector<cv::Point2d> top =
      ProjectGroundPolygon(cam, Circle(s.x_m, s.z_m, r), s.height_m);
  pts.insert(pts.end(), top.begin(), top.end());
  const std::vector<cv::Point2d> hull = ConvexHull(pts);
  const Region silhouette = RasterisePolygons({hull}, canvas.size());
  double u0 = 1e18, u1 = -1e18;
  for (const cv::Point2d& p : hull) {
    u0 = std::min(u0, p.x);
    u1 = std::max(u1, p.x);
  }
  const double view_az = AzimuthToCamera(s);
  PaintShaded(canvas, silhouette, s.colour_bgr, labels,
              [&](double u, double) { return RoundSideShade(layout.light, view_az, u, u0, u1); });
  const float top_shade = layout.light.Shade({0, 1, 0});
  PaintFlat(canvas, RasterisePolygons({top}, canvas.size()), s.colour_bgr * top_shade * 1.05f,
            labels);
  if (tyre_hole) {
    const Region hole = RasterisePolygons(
        {ProjectGroundPolygon(cam, Circle(s.x_m, s.z_m, 0.5 * r), s.height_m)}, canvas.size());
    PaintFlat(canvas, hole, s.colour_bgr * 0.35f, labels);
  }
  return silhouette;
}

// A tyre on its tread, facing yaw: the road shows through its hole (labelled road, not obstacle).
Region DrawStandingTyre(Canvas& canvas, const SceneLayout& layout, const SynthObstacleSpec& s,
                        Labels labels, bool with_rim, const cv::Vec3f& rim_colour) {
  const PinholeCamera& cam = layout.camera;
  const double R = 0.5 * s.height_m, tread = s.depth_m;
  const cv::Vec3d axle(std::sin(s.yaw_rad), 0.0, std::cos(s.yaw_rad));
  const cv::Vec3d across(std::cos(s.yaw_rad), 0.0, -std::sin(s.yaw_rad));
  const cv::Vec3d up(0.0, 1.0, 0.0);
  const cv::Vec3d centre(s.x_m, R, s.z_m);
  const cv::Vec3d to_camera = cv::Vec3d(0.0, cam.height_m, 0.0) - centre;
  const double near_sign = axle.dot(to_camera) >= 0 ? 1.0 : -1.0;
  auto ring = [&](double side, double radius) {
    std::vector<cv::Point2d> out;
    for (int i = 0; i < 32; ++i) {
      const double t = kTwoPi * i / 32;
      const cv::Vec3d p =
          centre + axle * (side * 0.5 * tread) + (across * std::cos(t) + up * std::sin(t)) * radius;
      out.push_back(cam.Project(p[0], p[1], std::max(0.3, p[2])));
    }
    return out;
  };
  std::vector<cv::Point2d> all = ring(1.0, R);
  const std::vector<cv::Point2d> far_outer = ring(-1.0, R);
  all.insert(all.end(), far_outer.begin(), far_outer.end());
  Region body = RasterisePolygons({ConvexHull(all)}, canvas.size());
  Region sidewall = RasterisePolygons({ring(near_sign, R)}, canvas.size());
  if (!with_rim) {
    Region hole = RasterisePolygons({ring(near_sign, 0.5 * R)}, canvas.size());
    IntersectWith(hole, RasterisePolygons({ring(-near_sign, 0.5 * R)}, canvas.size()));
    Subtract(body, hole);
    Subtract(sidewall, hole);
  }
  PaintFlat(canvas, body, s.colour_bgr * layout.light.Shade({0, 1, 0}) * 0.9f, labels);
  PaintFlat(canvas, sidewall, s.colour_bgr * layout.light.Shade(axle * near_sign), labels);
  if (with_rim) {
    PaintFlat(canvas, RasterisePolygons({ring(near_sign, 0.45 * R)}, canvas.size()),
              rim_colour * layout.light.Shade(axle * near_sign), labels);
  }
  return body;
}

Region DrawBall(Canvas& canvas, const SceneLayout& layout, const SynthObstacleSpec& s,
                Labels labels, const cv::Vec3f& stripe, int stripes) {
  const PinholeCamera& cam = layout.camera;
  const double r = 0.5 * s.height_m;
  const cv::Point2d c = cam.Project(s.x_m, r, s.z_m);
  const double rp = cam.PixelsForSize(r, s.z_m);
  const Region disc = RasteriseEllipse(c, {rp, rp}, 0, canvas.size());
  for (int y = 0; y < disc.roi.height; ++y) {
    const int fy = disc.roi.y + y;
    for (int x = 0; x < disc.roi.width; ++x) {
      if (!disc.mask(y, x)) continue;
      const int fx = disc.roi.x + x;
      const double dx = std::clamp((fx + 0.5 - c.x) / rp, -1.0, 1.0);
      const double dy = std::clamp((fy + 0.5 - c.y) / rp, -1.0, 1.0);
      const double dz = std::sqrt(std::max(0.0, 1.0 - dx * dx - dy * dy));
      const float shade = layout.light.Shade(cv::Vec3d(dx, -dy, -dz));
      const bool in_stripe = stripes > 0 && std::sin(stripes * std::atan2(dy, dx)) > 0.0;
      canvas.colour(fy, fx) = (in_stripe ? stripe : s.colour_bgr) * shade;
      canvas.instance_ids(fy, fx) = labels.instance_id;
      canvas.label_ids(fy, fx) = labels.label_id;
      canvas.surface(fy, fx) = static_cast<uchar>(Surface::kStanding);
    }
  }
  return disc;
}

// Toys, bags, debris: an irregular outline in the vertical plane facing the camera, flat bottom.
Region DrawIrregular(Canvas& canvas, const SceneLayout& layout, const SynthObstacleSpec& s,
                     Labels labels, Rng& rng) {
  const PinholeCamera& cam = layout.camera;
  const double view_az = AzimuthToCamera(s);
  const double ux = std::cos(view_az), uz = -std::sin(view_az);  // horizontal, across the view
  std::vector<double> amp(4), phase(4);
  for (int k = 0; k < 4; ++k) {
    amp[k] = rng.Uniform(0.0, 0.18 / (k + 1));
    phase[k] = rng.Uniform(0, kTwoPi);
  }
  std::vector<cv::Point2d> poly;
  constexpr int kPoints = 28;
  for (int i = 0; i < kPoints; ++i) {
    const double t = kTwoPi * i / kPoints;
    double r = 0.85;
    for (int k = 0; k < 4; ++k) r += amp[k] * std::sin((k + 2) * t + phase[k]);
    const double a = 0.5 * s.width_m * r * std::cos(t);
    const double y = std::clamp(0.5 * s.height_m * (1.0 + r / 0.85 * std::sin(t)), 0.0, s.height_m);
    poly.push_back(cam.Project(s.x_m + a * ux, y, s.z_m + a * uz));
  }
  const Region body = RasterisePolygons({poly}, canvas.size());
  const double u0 = body.roi.x, u1 = body.roi.x + body.roi.width;
  PaintShaded(canvas, body, s.colour_bgr, labels, [&](double u, double) {
    return 0.5f * (1.0f + RoundSideShade(layout.light, view_az, u, u0, u1));
  });
  // Toy details: a few patches of another colour inside the outline.
  static const std::vector<cv::Vec3f> kDetails = {
      {30, 30, 200}, {200, 120, 30}, {30, 200, 230}, {240, 240, 240}, {40, 40, 40}};
  for (int k = rng.UniformInt(0, 3); k > 0 && !body.empty(); --k) {
    const cv::Point2d c(body.roi.x + rng.Uniform(0.2, 0.8) * body.roi.width,
                        body.roi.y + rng.Uniform(0.2, 0.8) * body.roi.height);
    Region patch = RasteriseEllipse(
        c, {rng.Uniform(0.1, 0.3) * body.roi.width, rng.Uniform(0.1, 0.3) * body.roi.height},
        rng.Uniform(0, 180), canvas.size());
    IntersectWith(patch, body);
    PaintFlat(canvas, patch,
              rng.Pick(kDetails) *
                  layout.light.Shade(cv::Vec3d(std::sin(view_az), 0.3, std::cos(view_az))),
              labels);
  }
  return body;
}

std::vector<cv::Point2d> FootprintOf(const SynthObstacleSpec& s) {
  switch (s.shape) {
    case SynthShape::kBox:
      return Footprint(Solid{s.x_m, s.z_m, s.width_m, s.depth_m, s.height_m, s.yaw_rad, 0.0});
    case SynthShape::kTyreStanding:
    case SynthShape::kIrregular:
      return Footprint(Solid{s.x_m, s.z_m, s.width_m, s.depth_m, s.height_m, s.yaw_rad, 0.0});
    default:
      return Circle(s.x_m, s.z_m, 0.5 * s.width_m, 16);
  }
}

cv::Vec3f ObstacleColour(SynthShape shape, const cv::Vec3f& road, Rng& rng) {
  if (rng.Chance(0.3)) {  // camouflaged: close to the road's own colour
    const float k = static_cast<float>(rng.Uniform(0.8, 1.25));
    return cv::Vec3f(road[0] * k + static_cast<float>(rng.Uniform(-8, 8)),
                     road[1] * k + static_cast<float>(rng.Uniform(-8, 8)),
                     road[2] * k + static_cast<float>(rng.Uniform(-8, 8)));
  }
  if (shape == SynthShape::kTyreStanding || shape == SynthShape::kTyreLying) {
    const float level = static_cast<float>(rng.Uniform(22, 50));
    return {level, level, level};
  }
  static const std::vector<cv::Vec3f> kPalette = {
      {80, 130, 175},  {60, 105, 150},  {225, 225, 225}, {35, 35, 35},   {40, 40, 190},
      {170, 80, 30},   {50, 150, 60},   {40, 180, 220},  {30, 110, 230}, {90, 140, 160},
      {150, 150, 150}, {200, 120, 200}, {110, 120, 130}, {60, 90, 110}};
  return rng.Pick(kPalette) * static_cast<float>(rng.Uniform(0.8, 1.15));
}

// The obstacle's width, depth and height in metres for its shape, `size` its largest dimension.
void SampleDimensions(double size, Rng& rng, SynthObstacleSpec& s) {
  switch (s.shape) {
    case SynthShape::kBox:
      switch (rng.UniformInt(0, 3)) {
        case 0:
          s.width_m = size;
          s.depth_m = size * rng.Uniform(0.5, 1.0);
          s.height_m = size * rng.Uniform(0.5, 1.0);
          break;
        case 1:
          s.width_m = size;
          s.depth_m = size * 0.5;
          s.height_m = size * rng.Uniform(0.25, 0.35);
          break;  // brick
        case 2:
          s.width_m = size;
          s.depth_m = size * rng.Uniform(0.15, 0.3);
          s.height_m = size * rng.Uniform(0.08, 0.2);
          break;  // plank
        default:
          s.height_m = size;
          s.width_m = size * rng.Uniform(0.4, 0.8);
          s.depth_m = size * rng.Uniform(0.4, 0.8);  // upright
      }
      break;
    case SynthShape::kCylinder:
      s.height_m = size * rng.Uniform(0.6, 1.0);
      s.width_m = s.depth_m = size * rng.Uniform(0.3, 0.9);
      break;
    case SynthShape::kTyreStanding:
      s.height_m = s.width_m = size;
      s.depth_m = size * rng.Uniform(0.25, 0.4);
      break;
    case SynthShape::kTyreLying:
      s.width_m = s.depth_m = size;
      s.height_m = size * rng.Uniform(0.25, 0.4);
      break;
    case SynthShape::kBall:
      s.width_m = s.depth_m = s.height_m = size;
      break;
    case SynthShape::kIrregular:
      s.width_m = size * rng.Uniform(0.6, 1.0);
      s.height_m = size * rng.Uniform(0.3, 1.0);
      s.depth_m = s.width_m * rng.Uniform(0.3, 1.0);
      break;
  }
}

SynthObstacleSpec SampleOne(const SynthParams& p, const SceneLayout& layout, Rng& rng) {
  SynthObstacleSpec s;
  const double u = rng.Unit();
  s.shape = u < 0.3    ? SynthShape::kBox
            : u < 0.42 ? SynthShape::kCylinder
            : u < 0.52 ? SynthShape::kTyreStanding
            : u < 0.6  ? SynthShape::kTyreLying
            : u < 0.72 ? SynthShape::kBall
                       : SynthShape::kIrregular;
  const double size = rng.LogUniform(p.min_size_m, p.max_size_m);  // largest dimension
  SampleDimensions(size, rng, s);
  s.yaw_rad = rng.Uniform(-CV_PI, CV_PI);
  const double bottom_m = layout.camera.GroundDistanceAtRow(layout.size.height);
  const double z_lo =
      std::max(p.min_distance_m, bottom_m * 1.03 + 0.5 * std::max(s.width_m, s.depth_m));
  const double z_hi = std::min(p.max_distance_m, layout.road.end_m - 2.0);
  s.z_m = z_hi > z_lo ? rng.LogUniform(z_lo, z_hi) : z_lo;
  const double half_free = 0.5 * layout.road.width_m - 0.3 - 0.5 * std::max(s.width_m, s.depth_m);
  s.x_m = layout.road.CentreAt(s.z_m) + rng.Uniform(-1, 1) * std::max(0.0, half_free);
  s.colour_bgr = ObstacleColour(s.shape, layout.materials.road.base, rng);
  s.label_class = rng.UniformInt(2, 43);
  return s;
}

bool Fits(const SynthParams& p, const SceneLayout& layout, const SynthObstacleSpec& s,
          const std::vector<SynthObstacleSpec>& placed) {
  const PinholeCamera& cam = layout.camera;
  if (s.z_m > layout.road.end_m - 1.0 || s.z_m < cam.GroundDistanceAtRow(layout.size.height))
    return false;
  if (cam.PixelsForSize(s.height_m, s.z_m) < p.min_obstacle_height_px) return false;
  const double u = cam.Project(s.x_m, 0, s.z_m).x;
  if (u < 0.02 * layout.size.width || u > 0.98 * layout.size.width) return false;
  for (const SynthObstacleSpec& o : placed) {
    const double clearance =
        0.5 * (std::max(s.width_m, s.depth_m) + std::max(o.width_m, o.depth_m)) + 0.3;
    if (std::hypot(s.x_m - o.x_m, s.z_m - o.z_m) < clearance) return false;
  }
  return true;
}

}  // namespace

double NearestDistance(const SynthObstacleSpec& spec) {
  return spec.z_m - 0.5 * std::max(spec.width_m, spec.depth_m);
}

std::vector<SynthObstacleSpec> SampleObstacles(const SynthParams& params, const SceneLayout& layout,
                                               Rng& rng) {
  std::vector<SynthObstacleSpec> placed;
  const int count = rng.UniformInt(std::max(0, params.min_obstacles),
                                   std::max(params.min_obstacles, params.max_obstacles));
  for (int i = 0; i < count; ++i) {
    for (int attempt = 0; attempt < 40; ++attempt) {
      const SynthObstacleSpec s = SampleOne(params, layout, rng);
      if (Fits(params, layout, s, placed)) {
        placed.push_back(s);
        break;
      }
    }
  }
  return placed;
}

void DrawObstacle(Canvas& canvas, const SceneLayout& layout, const SynthObstacleSpec& spec,
                  Labels labels, Rng& rng) {
  const PinholeCamera& cam = layout.camera;
  // Contact shadow: a dark soft ellipse just around the footprint (ambient occlusion), then the
  // sun's cast shadow. Both stay free space.
  const cv::Point2d base = cam.Project(spec.x_m, 0.0, spec.z_m);
  const double foot = 0.5 * std::max(spec.width_m, spec.depth_m);
  const double ax = cam.PixelsForSize(foot * 1.2, spec.z_m);
  const double ay = std::max(0.8, cam.focal_px * cam.height_m * foot * 1.2 / (spec.z_m * spec.z_m));
  Darken(canvas, RasteriseEllipse(base, {ax, ay}, 0, canvas.size()),
         static_cast<float>(rng.Uniform(0.35, 0.6)), std::max(0.6, 0.35 * ay));
  if (layout.light.sunny) {
    Darken(canvas,
           RasterisePolygons({CastShadow(cam, FootprintOf(spec), spec.height_m, layout.light)},
                             canvas.size()),
           layout.light.shadow_strength, 0.8);
  }
  Region body;
  switch (spec.shape) {
    case SynthShape::kBox:
      body = DrawBox(canvas, layout, spec, labels);
      break;
    case SynthShape::kCylinder:
      body = DrawCylinder(canvas, layout, spec, labels, false);
      break;
    case SynthShape::kTyreLying:
      body = DrawCylinder(canvas, layout, spec, labels, true);
      break;
    case SynthShape::kTyreStanding: {
      const bool rim = rng.Chance(0.4);
      body = DrawStandingTyre(canvas, layout, spec, labels, rim,
                              cv::Vec3f(150, 150, 155) * static_cast<float>(rng.Uniform(0.7, 1.2)));
      break;
    }
    case SynthShape::kBall: {
      const int stripes = rng.Chance(0.4) ? rng.UniformInt(2, 4) : 0;
      body = DrawBall(canvas, layout, spec, labels, cv::Vec3f(230, 230, 230), stripes);
      break;
    }
    case SynthShape::kIrregular:
      body = DrawIrregular(canvas, layout, spec, labels, rng);
      break;
  }
  VerticalGradient(canvas, body, static_cast<float>(rng.Uniform(0.7, 0.9)),
                   static_cast<float>(rng.Uniform(1.0, 1.1)));
}

}  // namespace tod::synth
