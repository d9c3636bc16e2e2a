// The sliding-window grid of OLP (ALGORITHM.md §4.2 steps 5-6): scales with step sqrt(1/alpha),
// aspect ratios with step (1 + alpha) / (2 alpha), and the multistride (MS) change of the paper,
// which scales each window's stride by the region's stride factor.
#pragma once

#include <vector>

#include "core/base/types.h"
#include "core/proposals/edge_box_scorer.h"

namespace tod {

// One window shape. Edge Boxes' nominal extents: a window at (x, y) covers the inclusive pixel
// range [x, x + width] x [y, y + height], clamped to the map when scored.
struct WindowShape {
  int width = 0;
  int height = 0;
  int stride_x = 0;  // column stride, from the width
  int stride_y = 0;  // row stride, from the height
};

// Delta = max(min_stride, floor((1 - alpha) / (1 + alpha) * stride_factor * side)) (§4.2.6).
int WindowStride(int side, const EdgeBoxParams& params);

// All shapes in generation order: scale-major, then aspect index a = -arRad(tau_a) ..
// arRad(max_wide_aspect_ratio), tallest first (a = 0 is square).
std::vector<WindowShape> WindowShapes(int map_width, int map_height, const EdgeBoxParams& params);

// Positions x = 0, stride_x, ... while x < map_width - width + stride_x (rows likewise).
int WindowPositionCount(int map_size, int window_side, int stride);

// Number of windows the grid visits on a map of this size.
long long CountWindows(int map_width, int map_height, const EdgeBoxParams& params);

// Every grid window as the half-open pixel box it scores (clamped to the map), in generation
// order (shape, then column, then row). Meant for tests and small maps.
std::vector<Box> GenerateWindowGrid(int map_width, int map_height, const EdgeBoxParams& params);

}  // namespace tod
