// Geometry shared by obstacles and background clutter: sunlight, boxes in 3D with their visible
// faces, and shapes lying on the ground plane, all projected through the pinhole camera.
#pragma once

#include <algorithm>
#include <opencv2/core.hpp>
#include <vector>

#include "core/synth/synth_camera.h"
#include "core/synth/synth_canvas.h"

namespace tod::synth {

struct Lighting {
  bool sunny = true;
  cv::Vec3d to_sun{0.3, 0.8, 0.5};  // unit vector towards the sun (world axes)
  float ambient = 0.55f;            // fraction of light reaching surfaces facing away
  float direct = 0.45f;
  float shadow_strength = 0.45f;  // how much a cast shadow darkens the ground

  // Brightness factor of a surface with unit normal n.
  float Shade(const cv::Vec3d& n) const {
    return ambient + direct * static_cast<float>(std::max(0.0, n.dot(to_sun)));
  }
};

// A box standing on (or above) the road: centre (x, z) of its footprint, size along its own
// axes, rotated by yaw about the vertical.
struct Solid {
  double x = 0, z = 10;
  double width = 0.3, depth = 0.3, height = 0.3;
  double yaw = 0;
  double base_y = 0;
};

struct ShadedPolygon {
  std::vector<cv::Point2d> points;
  float shade = 1.0f;
};

// The faces of the box the camera sees (back faces culled), each with its Lambert shade.
std::vector<ShadedPolygon> VisibleBoxFaces(const PinholeCamera& camera, const Solid& box,
                                           const Lighting& light);
// Footprint corners (y = base_y) of the box in world coordinates (x, z).
std::vector<cv::Point2d> Footprint(const Solid& box);

// A polygon given on the ground plane (world x, z) at height y, projected to the image.
std::vector<cv::Point2d> ProjectGroundPolygon(const PinholeCamera& camera,
                                              const std::vector<cv::Point2d>& xz, double y = 0);
// Circle / ellipse on the ground, as a projected polygon.
std::vector<cv::Point2d> GroundEllipse(const PinholeCamera& camera, double cx, double cz, double rx,
                                       double rz, double angle, double y = 0);
// A strip of width `width_m` along a ground polyline (world x, z), projected; used for markings
// and scrawls so their width shrinks with distance.
std::vector<std::vector<cv::Point2d>> GroundStroke(const PinholeCamera& camera,
                                                   const std::vector<cv::Point2d>& xz,
                                                   double width_m);

// The shadow a convex object of this footprint and height casts on the ground, as an image
// polygon (convex hull of the footprint and the footprint moved away from the sun).
std::vector<cv::Point2d> CastShadow(const PinholeCamera& camera,
                                    const std::vector<cv::Point2d>& footprint_xz, double height,
                                    const Lighting& light);

}  // namespace tod::synth
