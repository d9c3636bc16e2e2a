// Small constructed edge maps shared by the proposals tests.
#pragma once

#include <opencv2/core.hpp>

namespace tod::testing {

// Draws the 1-pixel outline of the inclusive rectangle [x0, x1] x [y0, y1] with value v.
inline void DrawRectangleContour(cv::Mat1f& map, int x0, int y0, int x1, int y1, float v = 1.f) {
  for (int x = x0; x <= x1; ++x) map(y0, x) = map(y1, x) = v;
  for (int y = y0; y <= y1; ++y) map(y, x0) = map(y, x1) = v;
}

}  // namespace tod::testing
