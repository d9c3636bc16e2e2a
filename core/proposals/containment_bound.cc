#include "core/proposals/containment_bound.h"

#include <algorithm>
#include <cmath>

#include "core/proposals/fresh_buffer.h"

namespace tod {
ContainmentBound::ContainmentBound(const EdgeGroups& groups, const cv::Mat1f& edge_map,
                                   float edge_min_mag)
    : ContainmentBound(groups, FindEdgePixels(edge_map, edge_min_mag)) {}

ContainmentBound::ContainmentBound(const EdgeGroups& groups, const EdgePixels& edges) {
  const int width = edges.cols, height = edges.rows;
  const int n = groups.count();
  stride_ = static_cast<size_t>(height) + 1;
  std::vector<GroupBox> extents = GroupExtents(groups, edges);
  double total_magnitude = 0.0, total_edge = 0.0;
  for (int s = 1; s <= n; ++s) total_magnitude += groups.magnitude[s];
  // Row-major, the order of a full scan of the map: the same double sum.
  for (const float e : edges.row_value) total_edge += e;
  // The largest power of two that keeps every sum (each rounded-up group adds < 1 unit) below
  // 2^32, capped where the resolution stops mattering.
  const double capacity = 4294967295.0 - static_cast<double>(n) - 1.0;
  const double largest = std::max({total_magnitude, total_edge, 1.0});
  const int exponent = std::min(24, static_cast<int>(std::floor(std::log2(capacity / largest))));
  const double scale = std::ldexp(1.0, exponent);
  inverse_scale_ = 1.0 / scale;
  // The exact score is a handful of double operations on values up to the totals.
  margin_ = 1e-9 * (largest + 1.0);
  group_boxes_.reserve(n);
  for (int s = 1; s <= n; ++s) {
    extents[s].magnitude = static_cast<std::uint32_t>(std::ceil(groups.magnitude[s] * scale));
    if (extents[s].c1 >= 0) group_boxes_.push_back(extents[s]);
  }
  std::stable_sort(group_boxes_.begin(), group_boxes_.end(),
                   [](const GroupBox& a, const GroupBox& b) { return a.c0 < b.c0; });
  // Both integrals are built column by column (see fresh_buffer.h) as left column + running sum
  // of this column, in modular uint32 arithmetic: the ring's sums do not depend on the order of
  // the additions, so the values equal those of any other summation order (e.g. the 2-D
  // recurrence here = pixel + up + left - up_left).
  BuildCornerIntegral(groups, extents, width, height);
  BuildEdgeIntegral(edges, scale, width, height);
}

std::vector<ContainmentBound::GroupBox> ContainmentBound::GroupExtents(const EdgeGroups& groups,
                                                                       const EdgePixels& edges) {
  // Every grouped pixel is an edge pixel, and the column-major list meets a group's columns in
  // ascending order.
  std::vector<GroupBox> extents(static_cast<size_t>(groups.count()) + 1,
                                GroupBox{edges.cols, -1, edges.rows, -1});
  for (int c = 0; c < edges.cols; ++c) {
    for (int i = edges.col_begin[c]; i < edges.col_begin[c + 1]; ++i) {
      const int r = edges.col_row[i];
      const int s = groups.ids(r, c);
      if (s <= 0) continue;
      GroupBox& g = extents[s];
      if (g.c1 < 0) g.c0 = c;
      g.c1 = c;
      g.r0 = std::min(g.r0, r);
      g.r1 = std::max(g.r1, r);
    }
  }
  return extents;
}

void ContainmentBound::BuildCornerIntegral(const EdgeGroups& groups,
                                           const std::vector<GroupBox>& extents, int width,
                                           int height) {
  const int n = groups.count();
  // Group magnitudes at the four bounding-box corners, bucketed by integral column.
  struct CornerValue {
    int row = 0, corner = 0;
    std::uint32_t value = 0;
  };
  std::vector<int> corner_begin(static_cast<size_t>(width) + 2, 0);
  for (int s = 1; s <= n; ++s) {
    corner_begin[extents[s].c0 + 2] += 2;  // corners 0 and 2 in integral column c0 + 1
    corner_begin[extents[s].c1 + 2] += 2;  // corners 1 and 3 in integral column c1 + 1
  }
  for (int c = 0; c <= width; ++c) corner_begin[c + 1] += corner_begin[c];
  std::vector<CornerValue> corners(static_cast<size_t>(corner_begin[width + 1]));
  std::vector<int> next(corner_begin.begin(), corner_begin.end() - 1);
  for (int s = 1; s <= n; ++s) {
    const GroupBox& g = extents[s];
    const std::uint32_t q = g.magnitude;
    const int xs[4] = {g.c0, g.c1, g.c0, g.c1};
    const int ys[4] = {g.r0, g.r0, g.r1, g.r1};
    for (int k = 0; k < 4; ++k) corners[next[xs[k] + 1]++] = {ys[k] + 1, k, q};
  }
  ReserveFresh(cells_, (static_cast<size_t>(width) + 1) * stride_);
  Append(cells_, stride_);  // column 0: zero
  for (int c = 1; c <= width; ++c) {
    Cell* here = Append(cells_, stride_);  // zeroed, cache-resident: scatter, then sum in place
    const Cell* left = here - stride_;
    for (int i = corner_begin[c]; i < corner_begin[c + 1]; ++i) {
      here[corners[i].row].corner[corners[i].corner] += corners[i].value;
    }
    std::uint32_t sum0 = 0, sum1 = 0, sum2 = 0, sum3 = 0;
    for (int r = 1; r <= height; ++r) {
      sum0 += here[r].corner[0];
      sum1 += here[r].corner[1];
      sum2 += here[r].corner[2];
      sum3 += here[r].corner[3];
      here[r].corner[0] = left[r].corner[0] + sum0;
      here[r].corner[1] = left[r].corner[1] + sum1;
      here[r].corner[2] = left[r].corner[2] + sum2;
      here[r].corner[3] = left[r].corner[3] + sum3;
    }
  }
}

void ContainmentBound::BuildEdgeIntegral(const EdgePixels& edges, double scale, int width,
                                         int height) {
  // The edge integral only changes at edge pixels: between two of them a column is the left
  // column plus a constant.
  ReserveFresh(edges_, (static_cast<size_t>(width) + 1) * stride_);
  Append(edges_, stride_);  // column 0: zero
  for (int c = 1; c <= width; ++c) {
    std::uint32_t* here = Append(edges_, stride_);  // row 0: zero
    const std::uint32_t* left = here - stride_;
    std::uint32_t sum = 0;
    int r = 1;
    for (int i = edges.col_begin[c - 1]; i < edges.col_begin[c]; ++i) {
      const int row = edges.col_row[i] + 1;  // the first integral row that includes the pixel
      for (; r < row; ++r) here[r] = left[r] + sum;
      sum += static_cast<std::uint32_t>(std::floor(edges.col_value[i] * scale));
    }
    for (; r <= height; ++r) here[r] = left[r] + sum;
  }
}

bool ContainmentBound::InteriorTops(int c0, int c1, int box_height, int max_groups,
                                    std::vector<std::pair<int, int>>& tops,
                                    std::vector<ContainedStep>* steps) const {
  tops.clear();
  if (steps != nullptr) steps->clear();
  // Groups starting in the interior's columns [c0 + 1, c1 - 1].
  const auto first = std::lower_bound(group_boxes_.begin(), group_boxes_.end(), c0 + 1,
                                      [](const GroupBox& g, int column) { return g.c0 < column; });
  const auto last = std::upper_bound(first, group_boxes_.end(), c1 - 1,
                                     [](int column, const GroupBox& g) { return column < g.c0; });
  if (last - first > max_groups) return false;
  for (auto g = first; g != last; ++g) {
    if (g->c1 > c1 - 1) continue;
    // Interior rows [y + 1, y + box_height - 1] hold rows [r0, r1]: y in [r1 - h + 1, r0 - 1].
    const int begin = g->r1 - box_height + 1, end = g->r0;
    if (begin >= end) continue;
    tops.emplace_back(begin, end);
    if (steps != nullptr) {
      steps->push_back({begin, g->magnitude});
      steps->push_back({end, -static_cast<std::int64_t>(g->magnitude)});
    }
  }
  if (steps != nullptr) {
    std::sort(steps->begin(), steps->end(),
              [](const ContainedStep& a, const ContainedStep& b) { return a.y < b.y; });
  }
  std::sort(tops.begin(), tops.end());
  size_t merged = 0;
  for (size_t i = 0; i < tops.size(); ++i) {
    if (merged > 0 && tops[i].first <= tops[merged - 1].second) {
      tops[merged - 1].second = std::max(tops[merged - 1].second, tops[i].second);
    } else {
      tops[merged++] = tops[i];
    }
  }
  tops.resize(merged);
  return true;
}

}  // namespace tod
