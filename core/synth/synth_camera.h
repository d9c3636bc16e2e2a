// Pinhole camera over a flat road (world: X right, Y up from the road surface, Z forward; the
// optical axis is horizontal, so the horizon is one image row). A ground point at distance Z
// projects to row horizon + f * H / Z, and an object of size s at Z spans f * s / Z pixels:
// this is what makes an obstacle's size and row follow its distance.
#pragma once

#include <opencv2/core.hpp>

namespace tod::synth {

struct PinholeCamera {
  double focal_px = 0;     // f
  double center_x = 0;     // principal point column
  double horizon_row = 0;  // principal point row (= horizon for a level camera)
  double height_m = 1.4;   // H, camera above the road plane

  // Image position of world point (X, Y, Z); Z must be > 0.
  cv::Point2d Project(double x, double y, double z) const {
    return {center_x + focal_px * x / z, horizon_row + focal_px * (height_m - y) / z};
  }
  // Distance of the road point seen at image row `row` (row must be below the horizon).
  double GroundDistanceAtRow(double row) const { return focal_px * height_m / (row - horizon_row); }
  double RowOfGroundDistance(double z) const { return horizon_row + focal_px * height_m / z; }
  // Lateral world position of the road point seen at (column, row).
  double GroundLateralAt(double column, double row) const {
    return (column - center_x) * GroundDistanceAtRow(row) / focal_px;
  }
  // Pixel extent of a length `size_m` seen face-on at distance z.
  double PixelsForSize(double size_m, double z) const { return focal_px * size_m / z; }
  // Metres covered by one pixel on a surface at distance z (texture anti-aliasing).
  double MetresPerPixel(double z) const { return z / focal_px; }
};

}  // namespace tod::synth
