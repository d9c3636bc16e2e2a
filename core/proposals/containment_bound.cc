#include "core/proposals/containment_bound.h"

#include <algorithm>
#include <cmath>

namespace tod {
namespace {

// Running 2-D sums in place over a column-major (width + 1) x (height + 1) array whose first row
// and column are zero; unsigned overflow wraps, which keeps rectangle differences exact as long
// as every true rectangle sum stays below 2^32.
template <typename T, typename Get>
void Accumulate(std::vector<T>& cells, int width, int height, Get get) {
  const size_t stride = static_cast<size_t>(height) + 1;
  for (int c = 1; c <= width; ++c) {
    for (int r = 1; r <= height; ++r) {
      const size_t i = c * stride + r;
      get(cells[i], cells[i - 1], cells[i - stride], cells[i - stride - 1]);
    }
  }
}

}  // namespace

ContainmentBound::ContainmentBound(const EdgeGroups& groups, const cv::Mat1f& edge_map,
                                   float edge_min_mag) {
  const int width = edge_map.cols, height = edge_map.rows;
  const int n = groups.count();
  stride_ = static_cast<size_t>(height) + 1;
  // Bounding boxes of the groups.
  std::vector<int> x0(n + 1, width), x1(n + 1, -1), y0(n + 1, height), y1(n + 1, -1);
  for (int r = 0; r < height; ++r) {
    const int* ids = groups.ids[r];
    for (int c = 0; c < width; ++c) {
      const int s = ids[c];
      if (s <= 0) continue;
      x0[s] = std::min(x0[s], c);
      x1[s] = std::max(x1[s], c);
      y0[s] = std::min(y0[s], r);
      y1[s] = std::max(y1[s], r);
    }
  }
  double total_magnitude = 0.0, total_edge = 0.0;
  for (int s = 1; s <= n; ++s) total_magnitude += groups.magnitude[s];
  for (int r = 0; r < height; ++r) {
    const float* e = edge_map[r];
    for (int c = 0; c < width; ++c) {
      if (e[c] > edge_min_mag) total_edge += e[c];
    }
  }
  // The largest power of two that keeps every sum (each rounded-up group adds < 1 unit) below
  // 2^32, capped where the resolution stops mattering.
  const double capacity = 4294967295.0 - static_cast<double>(n) - 1.0;
  const double largest = std::max({total_magnitude, total_edge, 1.0});
  const int exponent = std::min(24, static_cast<int>(std::floor(std::log2(capacity / largest))));
  const double scale = std::ldexp(1.0, exponent);
  inverse_scale_ = 1.0 / scale;
  // The exact score is a handful of double operations on values up to the totals.
  margin_ = 1e-9 * (largest + 1.0);

  const size_t size = (static_cast<size_t>(width) + 1) * stride_;
  cells_.assign(size, Cell{});
  edges_.assign(size, 0u);
  for (int s = 1; s <= n; ++s) {
    const auto q = static_cast<std::uint32_t>(std::ceil(groups.magnitude[s] * scale));
    const int xs[4] = {x0[s], x1[s], x0[s], x1[s]};
    const int ys[4] = {y0[s], y0[s], y1[s], y1[s]};
    for (int k = 0; k < 4; ++k) cells_[Index(ys[k] + 1, xs[k] + 1)].corner[k] += q;
  }
  for (int r = 0; r < height; ++r) {
    const float* e = edge_map[r];
    for (int c = 0; c < width; ++c) {
      if (e[c] > edge_min_mag) {
        edges_[Index(r + 1, c + 1)] = static_cast<std::uint32_t>(std::floor(e[c] * scale));
      }
    }
  }
  Accumulate(cells_, width, height,
             [](Cell& here, const Cell& up, const Cell& left, const Cell& up_left) {
               for (int k = 0; k < 4; ++k)
                 here.corner[k] += up.corner[k] + left.corner[k] - up_left.corner[k];
             });
  Accumulate(edges_, width, height,
             [](std::uint32_t& here, std::uint32_t up, std::uint32_t left, std::uint32_t up_left) {
               here += up + left - up_left;
             });
}

}  // namespace tod
