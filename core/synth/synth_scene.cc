#include "core/synth/synth_scene.h"

#include <algorithm>
#include <cmath>

namespace tod::synth {
namespace {

cv::Vec3f Grey(double level, double tint_b = 0, double tint_r = 0) {
  return cv::Vec3f(static_cast<float>(level + tint_b), static_cast<float>(level),
                   static_cast<float>(level + tint_r));
}

GroundMaterial SampleRoadMaterial(Rng& rng, double road_width) {
  GroundMaterial m;
  const double level = rng.Uniform(68, 140);
  m.base = Grey(level, rng.Uniform(-5, 9), rng.Uniform(-6, 6));
  m.blotch_amp = static_cast<float>(rng.Uniform(0.03, 0.14));
  m.blotch_cell_m = rng.Uniform(1.5, 5.0);
  m.grain_amp = static_cast<float>(rng.Uniform(0.05, 0.2));
  m.grain_cell_m = rng.Uniform(0.03, 0.12);
  if (rng.Chance(0.18)) {  // paved street / yard
    m.tiles = true;
    m.tile_across_m = rng.Uniform(0.1, 0.25);
    m.tile_along_m = rng.Uniform(0.1, 0.22);
    m.tile_jitter = static_cast<float>(rng.Uniform(0.03, 0.12));
    m.joint_darkness = static_cast<float>(rng.Uniform(0.15, 0.45));
    if (rng.Chance(0.35))
      m.base = cv::Vec3f(static_cast<float>(level * 0.8), static_cast<float>(level * 0.85),
                         static_cast<float>(level * 1.1));
  }
  if (road_width > 6.0 && rng.Chance(0.6)) {
    const double lane = road_width / 4.0;  // two lanes: centres at +-width/4
    m.wheel_tracks_m = {-lane - 0.8, -lane + 0.8, lane - 0.8, lane + 0.8};
    m.wheel_track_darkness = static_cast<float>(rng.Uniform(0.02, 0.09));
  }
  return m;
}

GroundMaterial SampleSidewalkMaterial(Rng& rng) {
  GroundMaterial m;
  const double level = rng.Uniform(105, 185);
  m.base = rng.Chance(0.3) ? cv::Vec3f(static_cast<float>(level * 0.7),
                                       static_cast<float>(level * 0.75), static_cast<float>(level))
                           : Grey(level, rng.Uniform(-5, 5), rng.Uniform(-5, 5));
  m.blotch_amp = static_cast<float>(rng.Uniform(0.03, 0.1));
  m.grain_amp = static_cast<float>(rng.Uniform(0.04, 0.12));
  m.tiles = rng.Chance(0.7);
  const double slab = rng.Chance(0.5) ? rng.Uniform(0.25, 0.5) : rng.Uniform(0.1, 0.2);
  m.tile_across_m = slab;
  m.tile_along_m = slab * rng.Uniform(0.6, 1.2);
  m.joint_darkness = static_cast<float>(rng.Uniform(0.15, 0.4));
  return m;
}

GroundMaterial SampleVergeMaterial(Rng& rng) {
  GroundMaterial m;
  switch (rng.UniformInt(0, 3)) {
    case 0:  // grass
    case 1:
      m.base = cv::Vec3f(static_cast<float>(rng.Uniform(35, 70)),
                         static_cast<float>(rng.Uniform(85, 135)),
                         static_cast<float>(rng.Uniform(55, 100)));
      m.blotch_amp = 0.2f;
      m.grain_amp = 0.3f;
      m.grain_cell_m = 0.05;
      break;
    case 2: {  // gravel / dirt
      const double level = rng.Uniform(90, 150);
      m.base = cv::Vec3f(static_cast<float>(level * 0.8), static_cast<float>(level * 0.92),
                         static_cast<float>(level));
      m.blotch_amp = 0.15f;
      m.grain_amp = 0.3f;
      m.grain_cell_m = 0.04;
      break;
    }
    default:  // more asphalt (parking area)
      m.base = Grey(rng.Uniform(70, 130));
      m.blotch_amp = 0.1f;
      m.grain_amp = 0.12f;
  }
  return m;
}

RoadSide SampleSide(Rng& rng) {
  RoadSide side;
  side.curb_height_m = rng.Chance(0.8) ? rng.Uniform(0.08, 0.16) : 0.0;
  side.sidewalk_m = rng.Chance(0.8) ? rng.Uniform(1.2, 4.5) : 0.0;
  side.verge_m = rng.Uniform(0.5, 8.0);
  return side;
}

// A strip between two lateral boundaries along the sampled distances, at height y.
std::vector<cv::Point2d> Strip(const PinholeCamera& camera, const std::vector<double>& zs,
                               const std::function<double(double)>& inner,
                               const std::function<double(double)>& outer, double y) {
  std::vector<cv::Point2d> poly;
  poly.reserve(2 * zs.size());
  for (double z : zs) poly.push_back(camera.Project(inner(z), y, z));
  for (auto it = zs.rbegin(); it != zs.rend(); ++it)
    poly.push_back(camera.Project(outer(*it), y, *it));
  return poly;
}

// The vertical face of a curb along a road edge.
std::vector<cv::Point2d> CurbFace(const PinholeCamera& camera, const std::vector<double>& zs,
                                  const std::function<double(double)>& edge, double height) {
  std::vector<cv::Point2d> poly;
  for (double z : zs) poly.push_back(camera.Project(edge(z), 0.0, z));
  for (auto it = zs.rbegin(); it != zs.rend(); ++it)
    poly.push_back(camera.Project(edge(*it), height, *it));
  return poly;
}

}  // namespace

std::vector<double> SceneLayout::DepthSamples(int count) const {
  std::vector<double> zs(static_cast<std::size_t>(count));
  const double ratio = road.end_m / near_m;
  for (int i = 0; i < count; ++i)
    zs[i] = near_m * std::pow(ratio, static_cast<double>(i) / (count - 1));
  return zs;
}

SceneLayout SampleLayout(const SynthParams& params, Rng& rng) {
  SceneLayout layout;
  layout.size = cv::Size(params.width, params.height);
  const double j = std::max(0.0, params.camera_jitter);
  PinholeCamera& cam = layout.camera;
  cam.focal_px = params.focal_frac * params.width * (1.0 + j * rng.Uniform(-1, 1));
  cam.height_m = params.camera_height_m * (1.0 + j * rng.Uniform(-1, 1));
  cam.horizon_row = params.height * (params.horizon_frac + 0.25 * j * rng.Uniform(-1, 1));
  cam.center_x = params.width * (0.5 + 0.1 * j * rng.Uniform(-1, 1));
  // Ground just below the bottom row, so the road reaches the image edge.
  const double bottom_gap = std::max(1.0, params.height - cam.horizon_row);
  layout.near_m = 0.8 * cam.focal_px * cam.height_m / bottom_gap;

  RoadGeometry& road = layout.road;
  road.width_m = rng.Uniform(5.5, 13.0);
  road.centre_offset_m = 0.7 * rng.Uniform(-1, 1) * (0.5 * road.width_m - 1.2);
  road.curvature_per_m = rng.Chance(0.5) ? 0.0 : rng.Uniform(-1, 1) / 260.0;
  road.end_m = std::max(layout.near_m * 3.0, rng.LogUniform(35.0, 160.0));
  layout.left = SampleSide(rng);
  layout.right = SampleSide(rng);

  Lighting& light = layout.light;
  light.sunny = rng.Chance(0.55);
  const double elevation = rng.Uniform(20, 65) * CV_PI / 180.0;
  const double azimuth = rng.Uniform(0, 2 * CV_PI);
  light.to_sun = cv::Vec3d(std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                           std::cos(elevation) * std::cos(azimuth));
  if (light.sunny) {
    light.ambient = static_cast<float>(rng.Uniform(0.45, 0.6));
    light.direct = static_cast<float>(rng.Uniform(0.45, 0.7));
    light.shadow_strength = static_cast<float>(rng.Uniform(0.3, 0.55));
  } else {
    light.ambient = static_cast<float>(rng.Uniform(0.75, 0.9));
    light.direct = static_cast<float>(rng.Uniform(0.1, 0.25));
    light.shadow_strength = static_cast<float>(rng.Uniform(0.08, 0.2));
  }

  layout.materials.road = SampleRoadMaterial(rng, road.width_m);
  layout.materials.sidewalk = SampleSidewalkMaterial(rng);
  layout.materials.verge = SampleVergeMaterial(rng);
  layout.materials.far_ground = rng.Chance(0.5) ? layout.materials.verge : SampleVergeMaterial(rng);

  if (light.sunny && rng.Chance(0.7)) {  // blue sky
    layout.sky_top = cv::Vec3f(static_cast<float>(rng.Uniform(170, 230)),
                               static_cast<float>(rng.Uniform(120, 160)),
                               static_cast<float>(rng.Uniform(70, 110)));
    layout.sky_horizon = cv::Vec3f(static_cast<float>(rng.Uniform(200, 240)),
                                   static_cast<float>(rng.Uniform(190, 225)),
                                   static_cast<float>(rng.Uniform(170, 210)));
  } else {  // overcast
    const double level = rng.Uniform(150, 235);
    layout.sky_top = Grey(level * 0.9, 6, -4);
    layout.sky_horizon = Grey(level, 3, 0);
  }
  return layout;
}

namespace {

// The sky above the horizon row: the layout's gradient, modulated by the canvas detail noise.
void DrawSky(Canvas& canvas, const SceneLayout& layout, int horizon, float cloud_amp) {
  const PinholeCamera& cam = layout.camera;
  const int cols = canvas.colour.cols;
  for (int y = 0; y < horizon; ++y) {
    const float t = static_cast<float>(std::pow((y + 0.5) / std::max(1.0, cam.horizon_row), 0.7));
    const cv::Vec3f sky = layout.sky_top * (1.0f - t) + layout.sky_horizon * t;
    cv::Vec3f* c = canvas.colour.ptr<cv::Vec3f>(y);
    const float* d = canvas.detail.ptr<float>(y);
    for (int x = 0; x < cols; ++x) c[x] = sky * (1.0f + cloud_amp * d[x]);
  }
}

}  // namespace

void DrawSkyAndGround(Canvas& canvas, const SceneLayout& layout, Rng& rng) {
  const PinholeCamera& cam = layout.camera;
  const int rows = canvas.colour.rows;
  const int horizon = std::clamp(static_cast<int>(std::ceil(cam.horizon_row)), 0, rows);
  DrawSky(canvas, layout, horizon, static_cast<float>(rng.Uniform(0.02, 0.12)));
  // Everything below the horizon starts as far ground; nearer surfaces are painted over it.
  canvas.surface.rowRange(horizon, rows).setTo(static_cast<uchar>(Surface::kFarGround));

  const std::vector<double> zs = layout.DepthSamples(72);
  const RoadGeometry& road = layout.road;
  const cv::Size frame = canvas.size();
  struct SideGeometry {
    const RoadSide* side;
    double sign;  // -1 left, +1 right
    std::function<double(double)> edge;
  };
  const std::vector<SideGeometry> sides = {
      {&layout.left, -1.0, [&road](double z) { return road.LeftEdgeAt(z); }},
      {&layout.right, 1.0, [&road](double z) { return road.RightEdgeAt(z); }}};
  for (const SideGeometry& s : sides) {
    const double hc = s.side->curb_height_m;
    const double sw = s.side->sidewalk_m, vw = s.side->verge_m;
    const auto offset = [&s](double d) {
      return std::function<double(double)>([&s, d](double z) { return s.edge(z) + s.sign * d; });
    };
    Paint(canvas, RasterisePolygons({Strip(cam, zs, offset(sw), offset(sw + vw), hc)}, frame),
          cv::Vec3f(), 0, std::nullopt, Surface::kVerge);
    if (sw > 0) {
      Paint(canvas, RasterisePolygons({Strip(cam, zs, offset(0), offset(sw), hc)}, frame),
            cv::Vec3f(), 0, std::nullopt, Surface::kSidewalk);
    }
  }
  Paint(canvas,
        RasterisePolygons({Strip(
                              cam, zs, [&road](double z) { return road.LeftEdgeAt(z); },
                              [&road](double z) { return road.RightEdgeAt(z); }, 0.0)},
                          frame),
        cv::Vec3f(), 0, Labels{kRoadInstanceId, kRoadLabelId}, Surface::kRoad);

  const ValueNoise noise(rng);
  const std::uint64_t tile_seed = rng.Bits();
  ShadeGround(canvas, cam, layout.materials, noise, tile_seed,
              [&road](double z) { return road.CentreAt(z); });

  // Curb faces last: they are vertical, lit like walls facing the road.
  const float curb_level = static_cast<float>(rng.Uniform(120, 200));
  for (const SideGeometry& s : sides) {
    if (s.side->curb_height_m <= 0) continue;
    const float shade = layout.light.Shade(cv::Vec3d(-s.sign, 0.0, 0.0));
    Paint(canvas, RasterisePolygons({CurbFace(cam, zs, s.edge, s.side->curb_height_m)}, frame),
          cv::Vec3f(curb_level, curb_level, curb_level) * shade, 0.06f, Labels{0, 0},
          Surface::kCurb);
  }
}

}  // namespace tod::synth
