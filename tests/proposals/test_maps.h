// Small constructed edge maps shared by the proposals tests.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/proposals/edge_box_scorer.h"

namespace tod::testing {

// Draws the 1-pixel outline of the inclusive rectangle [x0, x1] x [y0, y1] with value v.
inline void DrawRectangleContour(cv::Mat1f& map, int x0, int y0, int x1, int y1, float v = 1.f) {
  for (int x = x0; x <= x1; ++x) map(y0, x) = map(y1, x) = v;
  for (int y = y0; y <= y1; ++y) map(y, x0) = map(y, x1) = v;
}

// Random closed contours and lines of random strength, some below edge_min_mag; max 1.
inline cv::Mat1f RandomContourMap(int width, int height, unsigned seed, int shapes) {
  std::mt19937 rng(seed);
  cv::Mat1f map(height, width, 0.f);
  std::uniform_int_distribution<int> x(0, width - 1), y(0, height - 1), rad(2, 20);
  std::uniform_real_distribution<float> mag(0.03f, 1.f);
  for (int i = 0; i < shapes; ++i) {
    cv::circle(map, {x(rng), y(rng)}, rad(rng), cv::Scalar(mag(rng)));
    cv::rectangle(map, cv::Rect(x(rng), y(rng), rad(rng), rad(rng)), cv::Scalar(mag(rng)));
    cv::line(map, {x(rng), y(rng)}, {x(rng), y(rng)}, cv::Scalar(mag(rng)));
  }
  return NormaliseToMax(map);
}

}  // namespace tod::testing
