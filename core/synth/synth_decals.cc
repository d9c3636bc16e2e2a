// Paint and blemishes on the road. None of it changes the labels: markings, patches, manholes,
// scrawls and shadows are free space in LAF, and they are the hard negatives a detector of
// small obstacles must not fire on.
#include <algorithm>
#include <cmath>

#include "core/synth/synth_scene.h"

namespace tod::synth {
namespace {

constexpr int kStrokeSamples = 12;

// A polyline along the road at a fixed lateral offset from its centre.
std::vector<cv::Point2d> AlongRoad(const RoadGeometry& road, double lateral, double z0, double z1) {
  std::vector<cv::Point2d> xz;
  for (int i = 0; i <= kStrokeSamples; ++i) {
    const double z = z0 + (z1 - z0) * i / kStrokeSamples;
    xz.emplace_back(road.CentreAt(z) + lateral, z);
  }
  return xz;
}

// Paints a stroke on road pixels only.
void RoadStroke(Canvas& canvas, const SceneLayout& layout, const std::vector<cv::Point2d>& xz,
                double width_m, const cv::Vec3f& colour, float alpha, float wear) {
  Region region = RasterisePolygons(GroundStroke(layout.camera, xz, width_m), canvas.size());
  RestrictToSurface(canvas, region, Surface::kRoad);
  Blend(canvas, region, colour, alpha, wear);
}

void RoadPolygon(Canvas& canvas, const SceneLayout& layout, const std::vector<cv::Point2d>& xz,
                 const cv::Vec3f& colour, float alpha, float texture) {
  Region region = RasterisePolygons({ProjectGroundPolygon(layout.camera, xz)}, canvas.size());
  RestrictToSurface(canvas, region, Surface::kRoad);
  Blend(canvas, region, colour, alpha, texture);
}

cv::Vec3f MarkingColour(Rng& rng) {
  if (rng.Chance(0.2)) {  // yellow
    return cv::Vec3f(static_cast<float>(rng.Uniform(40, 90)),
                     static_cast<float>(rng.Uniform(170, 210)),
                     static_cast<float>(rng.Uniform(200, 240)));
  }
  const float level = static_cast<float>(rng.Uniform(190, 245));
  return cv::Vec3f(level, level, level);
}

// A random point on the road surface between distances z0 and z1, `margin` inside the edges.
cv::Point2d RandomRoadPoint(const SceneLayout& layout, Rng& rng, double z0, double z1,
                            double margin) {
  const double z = rng.LogUniform(std::max(z0, layout.near_m), std::min(z1, layout.road.end_m));
  const double half = std::max(0.0, 0.5 * layout.road.width_m - margin);
  return {layout.road.CentreAt(z) + rng.Uniform(-half, half), z};
}

// A wandering ground polyline: scrawls and cracks.
std::vector<cv::Point2d> RandomWalk(cv::Point2d start, int steps, double step_m, double turn,
                                    Rng& rng) {
  std::vector<cv::Point2d> xz{start};
  double heading = rng.Uniform(0, 2 * CV_PI);
  for (int i = 0; i < steps; ++i) {
    heading += rng.Normal(0.0, turn);
    xz.push_back(xz.back() + cv::Point2d(std::cos(heading), std::sin(heading)) * step_m);
  }
  return xz;
}

void DrawManhole(Canvas& canvas, const SceneLayout& layout, Rng& rng, cv::Point2d at) {
  const double r = rng.Uniform(0.28, 0.4);
  const float level = static_cast<float>(rng.Uniform(45, 95));
  const cv::Vec3f metal(level, level * 1.02f, level * 1.05f);
  Region disc =
      RasterisePolygons({GroundEllipse(layout.camera, at.x, at.y, r, r, 0)}, canvas.size());
  RestrictToSurface(canvas, disc, Surface::kRoad);
  Blend(canvas, disc, metal * 1.2f, 0.9f, 0.1f);  // frame ring
  Region inner = RasterisePolygons(
      {GroundEllipse(layout.camera, at.x, at.y, r * 0.85, r * 0.85, 0)}, canvas.size());
  RestrictToSurface(canvas, inner, Surface::kRoad);
  Blend(canvas, inner, metal, 0.9f, 0.15f);
  // Cast pattern: a few parallel grooves across the lid.
  const int grooves = rng.UniformInt(3, 7);
  for (int i = 1; i < grooves; ++i) {
    const double off = -r * 0.8 + 1.6 * r * i / grooves;
    const double half = std::sqrt(std::max(0.0, 0.72 * r * r - off * off));
    RoadStroke(canvas, layout, {{at.x + off, at.y - half}, {at.x + off, at.y + half}}, 0.025,
               metal * 0.55f, 0.8f, 0.0f);
  }
}

void DrawDrain(Canvas& canvas, const SceneLayout& layout, Rng& rng, double z, bool left) {
  const double edge = left ? layout.road.LeftEdgeAt(z) + 0.35 : layout.road.RightEdgeAt(z) - 0.35;
  const double w = 0.3, l = rng.Uniform(0.4, 0.6);
  const float level = static_cast<float>(rng.Uniform(35, 70));
  RoadPolygon(canvas, layout,
              {{edge - w / 2, z}, {edge + w / 2, z}, {edge + w / 2, z + l}, {edge - w / 2, z + l}},
              cv::Vec3f(level, level, level), 0.95f, 0.05f);
  for (int i = 1; i < 7; ++i) {
    const double zz = z + l * i / 7.0;
    RoadStroke(canvas, layout, {{edge - w / 2, zz}, {edge + w / 2, zz}}, 0.02,
               cv::Vec3f(level, level, level) * 0.4f, 0.9f, 0.0f);
  }
}

}  // namespace

void DrawRoadMarkings(Canvas& canvas, const SceneLayout& layout, Rng& rng) {
  const RoadGeometry& road = layout.road;
  const double z0 = layout.near_m, z1 = road.end_m;
  const float wear = static_cast<float>(rng.Uniform(0.1, 0.5));
  const float alpha = static_cast<float>(rng.Uniform(0.55, 0.95));
  if (road.width_m > 6.0 && rng.Chance(0.6)) {  // centre line, dashed or solid
    const cv::Vec3f colour = MarkingColour(rng);
    const double width = rng.Uniform(0.1, 0.15);
    if (rng.Chance(0.7)) {
      const double dash = rng.Uniform(2.0, 4.0), gap = rng.Uniform(3.0, 8.0);
      for (double z = z0 - rng.Uniform(0, dash + gap); z < z1; z += dash + gap) {
        if (z + dash > z0)
          RoadStroke(canvas, layout, AlongRoad(road, 0.0, std::max(z, z0), std::min(z + dash, z1)),
                     width, colour, alpha, wear);
      }
    } else {
      RoadStroke(canvas, layout, AlongRoad(road, 0.0, z0, z1), width, colour, alpha, wear);
    }
  }
  if (rng.Chance(0.4)) {  // edge lines
    const cv::Vec3f colour = MarkingColour(rng);
    for (double side : {-1.0, 1.0}) {
      RoadStroke(canvas, layout, AlongRoad(road, side * (0.5 * road.width_m - 0.3), z0, z1), 0.12,
                 colour, alpha, wear);
    }
  }
  if (rng.Chance(0.2)) {  // stop line or zebra crossing across the road
    const double z = rng.Uniform(z0 + 3.0, std::max(z0 + 4.0, std::min(z1, 40.0)));
    const cv::Vec3f colour = MarkingColour(rng);
    if (rng.Chance(0.5)) {
      const std::vector<cv::Point2d> line = {{road.LeftEdgeAt(z), z}, {road.RightEdgeAt(z), z}};
      RoadStroke(canvas, layout, line, 0.4, colour, alpha, wear);
    } else {
      for (double x = -0.5 * road.width_m + 0.5; x < 0.5 * road.width_m - 0.5; x += 1.0) {
        RoadStroke(canvas, layout, AlongRoad(road, x + 0.25, z, z + 3.0), 0.5, colour, alpha, wear);
      }
    }
  }
  if (rng.Chance(0.2)) {  // parking bays along one edge
    const cv::Vec3f colour = MarkingColour(rng);
    const double side = rng.Chance(0.5) ? -1.0 : 1.0;
    const double bay = rng.Uniform(2.4, 2.8);
    for (double z = z0 + rng.Uniform(0, bay); z < std::min(z1, 45.0); z += bay) {
      const double edge = side < 0 ? road.LeftEdgeAt(z) : road.RightEdgeAt(z);
      RoadStroke(canvas, layout, {{edge, z}, {edge - side * 2.2, z}}, 0.1, colour, alpha, wear);
    }
  }
}

namespace {

// Repair patches: rectangles or blobs of fresher / older asphalt.
void DrawRepairPatches(Canvas& canvas, const SceneLayout& layout, Rng& rng) {
  const cv::Vec3f road_colour = layout.materials.road.base;
  for (int i = rng.UniformInt(0, 3); i > 0; --i) {
    const cv::Point2d c = RandomRoadPoint(layout, rng, layout.near_m, 60.0, 0.5);
    const double a = rng.Uniform(0.4, 3.0), b = rng.Uniform(0.4, 4.0), yaw = rng.Uniform(-0.3, 0.3);
    const float tone = static_cast<float>(rng.Uniform(0.65, 1.3));
    std::vector<cv::Point2d> xz;
    if (rng.Chance(0.6)) {
      const double cy = std::cos(yaw), sy = std::sin(yaw);
      for (const auto& [u, v] :
           std::vector<std::pair<double, double>>{{-a, -b}, {a, -b}, {a, b}, {-a, b}}) {
        xz.emplace_back(c.x + 0.5 * (cy * u - sy * v), c.y + 0.5 * (sy * u + cy * v));
      }
    } else {
      for (int k = 0; k < 10; ++k) {
        const double t = 2 * CV_PI * k / 10, r = rng.Uniform(0.6, 1.0);
        xz.emplace_back(c.x + 0.5 * a * r * std::cos(t), c.y + 0.5 * b * r * std::sin(t));
      }
    }
    RoadPolygon(canvas, layout, xz, road_colour * tone, static_cast<float>(rng.Uniform(0.6, 0.95)),
                0.08f);
  }
}

// Cracks and sealed joints (dark, thin), then chalk scrawls and spray-paint marks.
void DrawRoadStrokes(Canvas& canvas, const SceneLayout& layout, Rng& rng) {
  const cv::Vec3f road_colour = layout.materials.road.base;
  for (int i = rng.UniformInt(0, 4); i > 0; --i) {
    const cv::Point2d start = RandomRoadPoint(layout, rng, layout.near_m, 40.0, 0.3);
    RoadStroke(canvas, layout,
               RandomWalk(start, rng.UniformInt(4, 14), rng.Uniform(0.1, 0.4), 0.5, rng),
               rng.Uniform(0.01, 0.05), road_colour * 0.45f,
               static_cast<float>(rng.Uniform(0.4, 0.9)), 0.3f);
  }
  for (int i = rng.UniformInt(0, 2); i > 0; --i) {
    const cv::Point2d start = RandomRoadPoint(layout, rng, layout.near_m, 30.0, 0.5);
    static const std::vector<cv::Vec3f> kChalk = {
        {235, 235, 235}, {120, 200, 240}, {200, 140, 230}, {90, 90, 230}, {230, 180, 90}};
    RoadStroke(canvas, layout,
               RandomWalk(start, rng.UniformInt(6, 24), rng.Uniform(0.05, 0.25), 1.2, rng),
               rng.Uniform(0.02, 0.07), rng.Pick(kChalk),
               static_cast<float>(rng.Uniform(0.4, 0.85)), 0.4f);
  }
}

// Oil and water stains: soft, dark.
void DrawStains(Canvas& canvas, const SceneLayout& layout, Rng& rng) {
  for (int i = rng.UniformInt(0, 3); i > 0; --i) {
    const cv::Point2d c = RandomRoadPoint(layout, rng, layout.near_m, 50.0, 0.5);
    const Region stain =
        RasterisePolygons({GroundEllipse(layout.camera, c.x, c.y, rng.Uniform(0.2, 1.2),
                                         rng.Uniform(0.2, 1.5), rng.Uniform(0, CV_PI))},
                          canvas.size());
    Darken(canvas, stain, static_cast<float>(rng.Uniform(0.1, 0.35)),
           std::max(0.5, 0.3 * std::sqrt(static_cast<double>(stain.roi.area()))));
  }
}

// A tree canopy's shadow at ground point (x, z): a few overlapping soft ellipses.
void DrawCanopyShadow(Canvas& canvas, const SceneLayout& layout, Rng& rng, double x, double z) {
  std::vector<std::vector<cv::Point2d>> blobs;
  for (int k = rng.UniformInt(2, 5); k > 0; --k) {
    blobs.push_back(GroundEllipse(layout.camera, x + rng.Uniform(-1.5, 1.5),
                                  z + rng.Uniform(-1.5, 1.5), rng.Uniform(0.8, 2.5),
                                  rng.Uniform(0.8, 2.5), rng.Uniform(0, CV_PI)));
  }
  const Region r = RasterisePolygons(blobs, canvas.size());
  Darken(canvas, r, layout.light.shadow_strength, std::max(0.7, 0.02 * r.roi.width));
}

// A pole's or sign post's shadow from (x, z): a long thin strip across the road.
void DrawPoleShadow(Canvas& canvas, const SceneLayout& layout, Rng& rng, double x, double z) {
  const double yaw = rng.Uniform(-1.2, 1.2), len = rng.Uniform(4, 12);
  const std::vector<cv::Point2d> line = {{x, z},
                                         {x + len * std::sin(yaw), z + len * std::cos(yaw)}};
  Darken(
      canvas,
      RasterisePolygons(GroundStroke(layout.camera, line, rng.Uniform(0.1, 0.25)), canvas.size()),
      layout.light.shadow_strength, 0.7);
}

// A building's or wall's shadow at distance z: a large polygon reaching in from one side.
void DrawWallShadow(Canvas& canvas, const SceneLayout& layout, Rng& rng, double z) {
  const RoadGeometry& road = layout.road;
  const double side = rng.Chance(0.5) ? -1.0 : 1.0;
  const double far_edge = side < 0 ? road.LeftEdgeAt(z) - 10 : road.RightEdgeAt(z) + 10;
  const double reach = rng.Uniform(0.1, 0.6) * road.width_m;
  const double near_edge = (side < 0 ? road.LeftEdgeAt(z) : road.RightEdgeAt(z)) - side * reach;
  const double len = rng.Uniform(3, 20);
  Darken(canvas,
         RasterisePolygons({ProjectGroundPolygon(layout.camera, {{far_edge, z},
                                                                 {near_edge, z + len * 0.2},
                                                                 {near_edge, z + len},
                                                                 {far_edge, z + len}})},
                           canvas.size()),
         layout.light.shadow_strength, 1.0);
}

// Shadows of things outside the road: tree canopies, poles, building edges.
void DrawOutsideShadows(Canvas& canvas, const SceneLayout& layout, Rng& rng) {
  const RoadGeometry& road = layout.road;
  for (int i = rng.UniformInt(0, layout.light.sunny ? 4 : 1); i > 0; --i) {
    const double z = rng.LogUniform(layout.near_m, std::min(road.end_m, 60.0));
    const double x = road.CentreAt(z) + rng.Uniform(-0.7, 0.7) * road.width_m;
    switch (rng.UniformInt(0, 2)) {
      case 0:
        DrawCanopyShadow(canvas, layout, rng, x, z);
        break;
      case 1:
        DrawPoleShadow(canvas, layout, rng, x, z);
        break;
      default:
        DrawWallShadow(canvas, layout, rng, z);
    }
  }
}

}  // namespace

void DrawHardNegatives(Canvas& canvas, const SceneLayout& layout, Rng& rng) {
  DrawRepairPatches(canvas, layout, rng);
  for (int i = rng.UniformInt(0, 2); i > 0; --i) {
    DrawManhole(canvas, layout, rng, RandomRoadPoint(layout, rng, layout.near_m, 50.0, 1.0));
  }
  if (rng.Chance(0.4))
    DrawDrain(canvas, layout, rng, rng.Uniform(layout.near_m, 30.0), rng.Chance(0.5));
  DrawRoadStrokes(canvas, layout, rng);
  DrawStains(canvas, layout, rng);
  DrawOutsideShadows(canvas, layout, rng);
}

}  // namespace tod::synth
