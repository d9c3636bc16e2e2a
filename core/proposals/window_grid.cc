#include "core/proposals/window_grid.h"

#include <algorithm>
#include <cmath>

namespace tod {

int WindowStride(int side, const EdgeBoxParams& params) {
  const float ratio = (1.f - params.alpha) / (1.f + params.alpha);
  const int stride = static_cast<int>(ratio * params.stride_factor * static_cast<float>(side));
  return std::max({params.min_stride, stride, 1});  // >= 1 keeps the walk finite whatever the
                                                    // configuration
}

std::vector<WindowShape> WindowShapes(int map_width, int map_height, const EdgeBoxParams& params) {
  std::vector<WindowShape> shapes;
  if (map_width <= 0 || map_height <= 0 || !(params.alpha > 0.f && params.alpha < 1.f) ||
      !(params.min_box_area > 0.f) || !(params.max_aspect_ratio >= 1.f)) {
    return shapes;
  }
  const float scale_step = std::sqrt(1.f / params.alpha);
  const float aspect_step = (1.f + params.alpha) / (2.f * params.alpha);
  const float min_side = std::sqrt(params.min_box_area);
  const auto aspect_radius_for = [&](float bound) {
    return static_cast<int>(std::log(bound) / std::log(aspect_step * aspect_step));
  };
  const int tall_radius = aspect_radius_for(params.max_aspect_ratio);
  const int wide_radius = params.max_wide_aspect_ratio > 0.f
                              ? aspect_radius_for(std::max(params.max_wide_aspect_ratio, 1.f))
                              : tall_radius;
  const int scale_count = static_cast<int>(
      std::ceil(std::log(static_cast<float>(std::max(map_width, map_height)) / min_side) /
                std::log(scale_step)));
  for (int s = 0; s < scale_count; ++s) {
    const float side = min_side * std::pow(scale_step, static_cast<float>(s));
    for (int a = -tall_radius; a <= wide_radius; ++a) {
      const float aspect = std::pow(aspect_step, static_cast<float>(a));
      WindowShape shape;
      shape.height = static_cast<int>(side / aspect);
      shape.width = static_cast<int>(side * aspect);
      shape.stride_y = WindowStride(shape.height, params);
      shape.stride_x = WindowStride(shape.width, params);
      shapes.push_back(shape);
    }
  }
  return shapes;
}

int WindowPositionCount(int map_size, int window_side, int stride) {
  const int limit = map_size - window_side + stride;  // exclusive bound on the position
  if (limit <= 0 || stride <= 0) return 0;
  return (limit + stride - 1) / stride;
}

long long CountWindows(int map_width, int map_height, const EdgeBoxParams& params) {
  long long total = 0;
  for (const WindowShape& s : WindowShapes(map_width, map_height, params)) {
    total += static_cast<long long>(WindowPositionCount(map_width, s.width, s.stride_x)) *
             WindowPositionCount(map_height, s.height, s.stride_y);
  }
  return total;
}

std::vector<Box> GenerateWindowGrid(int map_width, int map_height, const EdgeBoxParams& params) {
  std::vector<Box> boxes;
  for (const WindowShape& s : WindowShapes(map_width, map_height, params)) {
    for (int x = 0; x < map_width - s.width + s.stride_x; x += s.stride_x) {
      for (int y = 0; y < map_height - s.height + s.stride_y; y += s.stride_y) {
        const int x1 = std::min(x + s.width, map_width - 1);
        const int y1 = std::min(y + s.height, map_height - 1);
        boxes.push_back(Box{x, y, x1 - x + 1, y1 - y + 1});
      }
    }
  }
  return boxes;
}

}  // namespace tod
