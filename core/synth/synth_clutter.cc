// Background clutter: everything standing beside or beyond the road. Labelled 0 (ignore), as
// in LAF where only free space and obstacles are annotated. Each item is returned with its
// nearest distance so it can be drawn far to near together with the obstacles.
#include <algorithm>
#include <cmath>

#include "core/synth/synth_scene.h"

namespace tod::synth {
namespace {

const Labels kBackground{0, 0};

cv::Vec3f FacadeColour(Rng& rng) {
  static const std::vector<cv::Vec3f> kPalette = {
      {150, 160, 170}, {110, 130, 160}, {90, 100, 120},  {180, 190, 200}, {120, 140, 150},
      {70, 80, 140},   {160, 170, 160}, {200, 205, 210}, {100, 110, 110}, {130, 160, 200}};
  const cv::Vec3f c = rng.Pick(kPalette);
  return c * static_cast<float>(rng.Uniform(0.75, 1.15));
}

cv::Vec3f FoliageColour(Rng& rng) {
  return cv::Vec3f(static_cast<float>(rng.Uniform(25, 60)),
                   static_cast<float>(rng.Uniform(60, 120)),
                   static_cast<float>(rng.Uniform(35, 80)));
}

// A vertical rectangle facing the camera at distance z, spanning x0..x1 and y0..y1 (world).
std::vector<cv::Point2d> FrontQuad(const PinholeCamera& cam, double x0, double x1, double y0,
                                   double y1, double z) {
  return {cam.Project(x0, y0, z), cam.Project(x1, y0, z), cam.Project(x1, y1, z),
          cam.Project(x0, y1, z)};
}

// A vertical rectangle parallel to the road axis at lateral x, spanning z0..z1 and y0..y1.
std::vector<cv::Point2d> SideQuad(const PinholeCamera& cam, double x, double z0, double z1,
                                  double y0, double y1) {
  z0 = std::max(z0, 0.3);
  z1 = std::max(z1, 0.3);
  return {cam.Project(x, y0, z0), cam.Project(x, y0, z1), cam.Project(x, y1, z1),
          cam.Project(x, y1, z0)};
}

void PaintQuad(Canvas& canvas, const std::vector<cv::Point2d>& quad, const cv::Vec3f& colour,
               float texture) {
  Paint(canvas, RasterisePolygons({quad}, canvas.size()), colour, texture, kBackground,
        Surface::kStanding);
}

// Windows on a facade, given as a function from facade coordinates (along, up) to the image.
template <typename ToImage>
void PaintWindows(Canvas& canvas, double length, double height, double spacing_along,
                  double spacing_up, const cv::Vec3f& glass, ToImage to_image) {
  int count = 0;
  for (double up = 1.0; up + 1.5 < height && count < 240; up += spacing_up) {
    for (double a = 0.8; a + 1.2 < length && count < 240; a += spacing_along, ++count) {
      const std::vector<cv::Point2d> quad = {to_image(a, up), to_image(a + 1.2, up),
                                             to_image(a + 1.2, up + 1.5), to_image(a, up + 1.5)};
      const double w = std::abs(quad[1].x - quad[0].x), h = std::abs(quad[3].y - quad[0].y);
      if (w < 1.5 || h < 1.5) return;  // too small to see: the facade texture stands in
      PaintQuad(canvas, quad, glass, 0.1f);
    }
  }
}

void AddSkyline(const SceneLayout& layout, Rng& rng, std::vector<StandingItem>& items) {
  const PinholeCamera& cam = layout.camera;
  const double z = layout.road.end_m;
  const double x_min = (0.0 - cam.center_x) * z / cam.focal_px - 10.0;
  const double x_max = (layout.size.width - cam.center_x) * z / cam.focal_px + 10.0;
  for (double x = x_min; x < x_max;) {
    const double w = rng.Uniform(4.0, 25.0);
    const double zz = z + rng.Uniform(0.0, 3.0);
    const int kind = rng.UniformInt(0, 9);
    const cv::Vec3f facade = FacadeColour(rng);
    const cv::Vec3f foliage = FoliageColour(rng);
    const cv::Vec3f bark = cv::Vec3f(40, 55, 70) * static_cast<float>(rng.Uniform(0.7, 1.3));
    const double h = kind < 5   ? rng.Uniform(4, 25)
                     : kind < 8 ? rng.Uniform(5, 14)
                                : rng.Uniform(1.5, 3.5);
    const cv::Vec3f glass = cv::Vec3f(60, 55, 50) * static_cast<float>(rng.Uniform(0.6, 1.6));
    std::vector<double> blobs;
    for (int k = 0; k < 6; ++k) blobs.push_back(rng.Uniform(0, 1));
    items.push_back({zz, [=, &cam](Canvas& canvas) {
                       if (kind < 5) {  // building with windows
                         PaintQuad(canvas, FrontQuad(cam, x, x + w, 0, h, zz), facade, 0.08f);
                         PaintWindows(canvas, w, h, 3.0, 3.0, glass, [&](double a, double up) {
                           return cam.Project(x + a, up, zz);
                         });
                       } else if (kind < 8) {  // tree line: overlapping canopy ellipses on trunks
                         std::vector<std::vector<cv::Point2d>> canopies, trunks;
                         for (std::size_t k = 0; k < blobs.size(); ++k) {
                           const double cx = x + w * (k + 0.5) / blobs.size();
                           const double r = 0.25 * w + 0.15 * w * blobs[k];
                           const cv::Point2d c = cam.Project(cx, h - r, zz);
                           const double rp = cam.PixelsForSize(r, zz);
                           constexpr int kSeg = 20;
                           std::vector<cv::Point2d> poly;
                           for (int s = 0; s < kSeg; ++s) {
                             const double t = 2 * CV_PI * s / kSeg;
                             poly.emplace_back(c.x + rp * std::cos(t), c.y + rp * std::sin(t));
                           }
                           canopies.push_back(poly);
                           trunks.push_back(FrontQuad(cam, cx - 0.15, cx + 0.15, 0, h - r, zz));
                         }
                         Paint(canvas, RasterisePolygons(trunks, canvas.size()), bark, 0.2f,
                               kBackground, Surface::kStanding);
                         Paint(canvas, RasterisePolygons(canopies, canvas.size()), foliage, 0.35f,
                               kBackground, Surface::kStanding);
                       } else {  // wall or hedge
                         PaintQuad(canvas, FrontQuad(cam, x, x + w, 0, h, zz),
                                   blobs[0] < 0.5 ? facade : foliage, 0.2f);
                       }
                     }});
    x += w + (rng.Chance(0.15) ? rng.Uniform(2, 15) : 0.0);
  }
}

// Facades along one side of the road.
void AddFacades(const SceneLayout& layout, const RoadSide& side, double sign, Rng& rng,
                std::vector<StandingItem>& items) {
  const PinholeCamera& cam = layout.camera;
  for (double z = rng.Uniform(2.0, 20.0); z < layout.road.end_m;) {
    const double len = rng.Uniform(8, 30), h = rng.Uniform(3.5, 20);
    const double edge = sign < 0 ? layout.road.LeftEdgeAt(z) : layout.road.RightEdgeAt(z);
    const double x = edge + sign * (side.OuterOffset() + rng.Uniform(0.3, 6.0));
    const double z1 = std::min(z + len, layout.road.end_m + 5.0);
    const cv::Vec3f colour = FacadeColour(rng) * layout.light.Shade(cv::Vec3d(-sign, 0, 0));
    const cv::Vec3f glass = cv::Vec3f(55, 50, 45) * static_cast<float>(rng.Uniform(0.6, 1.8));
    const double spacing = rng.Uniform(2.5, 4.0);
    items.push_back({z, [=, &cam](Canvas& canvas) {
                       PaintQuad(canvas, SideQuad(cam, x, z, z1, 0, h), colour, 0.08f);
                       PaintWindows(canvas, z1 - z, h, spacing, 3.0, glass,
                                    [&](double a, double up) {
                                      return cam.Project(x, up, std::max(0.3, z + a));
                                    });
                     }});
    z = z1 + (rng.Chance(0.5) ? rng.Uniform(1, 12) : 0.0);
  }
}

void AddTrees(const SceneLayout& layout, const RoadSide& side, double sign, Rng& rng,
              std::vector<StandingItem>& items) {
  const PinholeCamera& cam = layout.camera;
  for (int i = rng.UniformInt(0, 5); i > 0; --i) {
    const double z = rng.LogUniform(std::max(3.0, layout.near_m * 0.7), layout.road.end_m);
    const double edge = sign < 0 ? layout.road.LeftEdgeAt(z) : layout.road.RightEdgeAt(z);
    const double x =
        edge + sign * (side.sidewalk_m + rng.Uniform(0.3, std::max(0.4, side.verge_m)));
    const double trunk_h = rng.Uniform(1.5, 3.5), r = rng.Uniform(1.2, 3.5),
                 tw = rng.Uniform(0.2, 0.45);
    const cv::Vec3f bark = cv::Vec3f(40, 55, 70) * static_cast<float>(rng.Uniform(0.7, 1.3));
    const cv::Vec3f foliage = FoliageColour(rng);
    std::vector<cv::Point3d> lobes;
    for (int k = rng.UniformInt(3, 6); k > 0; --k) {
      lobes.emplace_back(rng.Uniform(-0.5, 0.5) * r, rng.Uniform(-0.3, 0.5) * r,
                         rng.Uniform(0.5, 0.8) * r);
    }
    items.push_back({z - r, [=, &cam](Canvas& canvas) {
                       PaintQuad(canvas,
                                 FrontQuad(cam, x - tw / 2, x + tw / 2, 0, trunk_h + r * 0.5, z),
                                 bark, 0.2f);
                       std::vector<std::vector<cv::Point2d>> canopy;
                       for (const cv::Point3d& l : lobes) {
                         const cv::Point2d c = cam.Project(x + l.x, trunk_h + r + l.y, z);
                         const double rp = cam.PixelsForSize(l.z, z);
                         std::vector<cv::Point2d> poly;
                         for (int s = 0; s < 20; ++s) {
                           const double t = 2 * CV_PI * s / 20;
                           poly.emplace_back(c.x + rp * std::cos(t), c.y + rp * std::sin(t));
                         }
                         canopy.push_back(poly);
                       }
                       Paint(canvas, RasterisePolygons(canopy, canvas.size()), foliage, 0.4f,
                             kBackground, Surface::kStanding);
                     }});
  }
}

void AddPolesAndBollards(const SceneLayout& layout, const RoadSide& side, double sign, Rng& rng,
                         std::vector<StandingItem>& items) {
  const PinholeCamera& cam = layout.camera;
  for (int i = rng.UniformInt(0, 3); i > 0; --i) {  // lamp posts and sign posts
    const double z = rng.LogUniform(std::max(3.0, layout.near_m), layout.road.end_m);
    const double edge = sign < 0 ? layout.road.LeftEdgeAt(z) : layout.road.RightEdgeAt(z);
    const double x = edge + sign * std::max(0.4, side.sidewalk_m - 0.4);
    const double h = rng.Uniform(2.5, 9.0), w = rng.Uniform(0.08, 0.2);
    const bool sign_plate = rng.Chance(0.5);
    const cv::Vec3f metal = cv::Vec3f(120, 120, 120) * static_cast<float>(rng.Uniform(0.5, 1.4));
    static const std::vector<cv::Vec3f> kSigns = {
        {40, 40, 200}, {180, 90, 30}, {230, 230, 230}, {30, 180, 220}};
    const cv::Vec3f plate = rng.Pick(kSigns);
    items.push_back({z, [=, &cam](Canvas& canvas) {
                       PaintQuad(canvas, FrontQuad(cam, x - w / 2, x + w / 2, 0, h, z), metal,
                                 0.05f);
                       if (sign_plate)
                         PaintQuad(canvas, FrontQuad(cam, x - 0.35, x + 0.35, h - 0.8, h - 0.1, z),
                                   plate, 0.05f);
                     }});
  }
  if (side.sidewalk_m > 0 && rng.Chance(0.25)) {  // a row of bollards at the curb
    const double z0 = rng.Uniform(layout.near_m, 25.0), step = rng.Uniform(1.5, 3.0);
    const double h = rng.Uniform(0.7, 1.0), w = rng.Uniform(0.1, 0.18);
    const cv::Vec3f colour = cv::Vec3f(90, 90, 90) * static_cast<float>(rng.Uniform(0.5, 2.2));
    for (double z = z0; z < z0 + rng.Uniform(5, 30); z += step) {
      const double x =
          (sign < 0 ? layout.road.LeftEdgeAt(z) : layout.road.RightEdgeAt(z)) + sign * 0.35;
      items.push_back({z, [=, &cam, &layout](Canvas& canvas) {
                         const Solid post{x, z, w, w, h, 0.0, side.curb_height_m};
                         for (const ShadedPolygon& f : VisibleBoxFaces(cam, post, layout.light)) {
                           PaintQuad(canvas, f.points, colour * f.shade, 0.05f);
                         }
                       }});
    }
  }
}

void AddParkedCars(const SceneLayout& layout, const RoadSide& side, double sign, Rng& rng,
                   std::vector<StandingItem>& items) {
  if (side.verge_m < 2.4 || !rng.Chance(0.5)) return;
  const PinholeCamera& cam = layout.camera;
  static const std::vector<cv::Vec3f> kPaint = {{30, 30, 30},   {200, 200, 200}, {40, 40, 150},
                                                {120, 60, 30},  {140, 140, 140}, {60, 110, 60},
                                                {180, 170, 160}};
  for (double z = rng.Uniform(layout.near_m, 30.0); z < layout.road.end_m;
       z += rng.Uniform(5.0, 15.0)) {
    const double edge = sign < 0 ? layout.road.LeftEdgeAt(z) : layout.road.RightEdgeAt(z);
    const double x = edge + sign * (side.sidewalk_m + 1.2);
    const cv::Vec3f paint = rng.Pick(kPaint);
    const double yaw = rng.Uniform(-0.08, 0.08);
    items.push_back(
        {z - 2.2, [=, &cam, &layout](Canvas& canvas) {
           const Solid body{x, z, 1.8, 4.3, 0.85, yaw, 0.3};
           const Solid cabin{x, z + 0.2, 1.6, 2.3, 0.6, yaw, 1.15};
           for (const ShadedPolygon& f : VisibleBoxFaces(cam, body, layout.light)) {
             PaintQuad(canvas, f.points, paint * f.shade, 0.03f);
           }
           for (const ShadedPolygon& f : VisibleBoxFaces(cam, cabin, layout.light)) {
             PaintQuad(canvas, f.points, cv::Vec3f(50, 45, 40) * (0.5f + f.shade), 0.05f);
           }
           // Wheels on the side facing the road.
           for (double dz : {-1.35, 1.35}) {
             const cv::Point2d c = cam.Project(x - sign * 0.9, 0.33, std::max(0.5, z + dz));
             const double r = cam.PixelsForSize(0.33, std::max(0.5, z + dz));
             Paint(canvas, RasteriseEllipse(c, {r * 0.5, r}, 0, canvas.size()),
                   cv::Vec3f(25, 25, 25), 0.05f, kBackground, Surface::kStanding);
           }
         }});
  }
}

void AddFenceOrHedge(const SceneLayout& layout, const RoadSide& side, double sign, Rng& rng,
                     std::vector<StandingItem>& items) {
  if (!rng.Chance(0.35)) return;
  const PinholeCamera& cam = layout.camera;
  const double z0 = rng.Uniform(2.0, 20.0),
               z1 = std::min(layout.road.end_m, z0 + rng.Uniform(10, 60));
  const double edge = sign < 0 ? layout.road.LeftEdgeAt(z0) : layout.road.RightEdgeAt(z0);
  const double x = edge + sign * (side.sidewalk_m + 0.2);
  const double h = rng.Uniform(0.9, 2.0);
  const bool hedge = rng.Chance(0.4);
  const cv::Vec3f colour =
      hedge ? FoliageColour(rng)
            : cv::Vec3f(110, 110, 110) * static_cast<float>(rng.Uniform(0.4, 1.6));
  const double post_step = rng.Uniform(2.0, 3.0);
  items.push_back({z0, [=, &cam](Canvas& canvas) {
                     if (hedge) {
                       PaintQuad(canvas, SideQuad(cam, x, z0, z1, 0, h), colour, 0.4f);
                       return;
                     }
                     for (double y : {h * 0.5, h - 0.05})
                       PaintQuad(canvas, SideQuad(cam, x, z0, z1, y - 0.05, y + 0.05), colour,
                                 0.05f);
                     for (double z = z0; z <= z1; z += post_step) {
                       PaintQuad(canvas, SideQuad(cam, x, z, z + 0.08, 0, h), colour * 0.8f, 0.05f);
                     }
                   }});
}

}  // namespace

std::vector<StandingItem> SampleClutter(const SceneLayout& layout, Rng& rng) {
  std::vector<StandingItem> items;
  AddSkyline(layout, rng, items);
  for (const auto& [side, sign] : {std::pair{&layout.left, -1.0}, std::pair{&layout.right, 1.0}}) {
    Rng side_rng = rng.Fork();
    if (side_rng.Chance(0.65)) AddFacades(layout, *side, sign, side_rng, items);
    AddTrees(layout, *side, sign, side_rng, items);
    AddPolesAndBollards(layout, *side, sign, side_rng, items);
    AddParkedCars(layout, *side, sign, side_rng, items);
    AddFenceOrHedge(layout, *side, sign, side_rng, items);
  }
  return items;
}

}  // namespace tod::synth
