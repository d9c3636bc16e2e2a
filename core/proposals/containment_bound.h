// A cheap, exact upper bound on a window's final Edge Boxes score (ALGORITHM.md §4.2.4), used to
// skip the boundary-affinity walk of windows that cannot reach min_score.
//
// Why it holds: every group touching one of the four box sides gets weight 1, so a group anchored
// inside the box survives the walk with weight < 1 only if it does not touch the sides. Groups
// are 8-connected (the greedy walk and the dissolution both add 8-neighbours of member pixels),
// so a group with its anchor inside that does not touch the sides lies entirely in the strict
// interior [r0 + 1, r1 - 1] x [c0 + 1, c1 - 1]. Hence
//   v - removed <= sum of m_s over groups inside the strict interior - edges of the centre box,
// and a group inside the interior has all four corners of its bounding box there. Summing m_s at
// one corner (one integral image per corner) over-counts only groups that stick out elsewhere, so
// the minimum over the four corner sums bounds the first term from above.
//
// The sums are kept in 32-bit fixed point with group magnitudes rounded up and edge values
// rounded down, so the bound is never below the true value; integer rectangle sums are exact
// (modular arithmetic, totals kept below 2^32), and the caller adds a margin that covers the
// double rounding of the exact score.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/proposals/edge_groups.h"

namespace tod {

class ContainmentBound {
 public:
  ContainmentBound() = default;
  // edge_map: finite values; edge pixels are those > edge_min_mag (as in the score).
  ContainmentBound(const EdgeGroups& groups, const cv::Mat1f& edge_map, float edge_min_mag);

  // Upper bound on v - removed of the clamped inclusive window [r0, r1] x [c0, c1] whose centre
  // box is [ir0, ir1] x [ic0, ic1], including the rounding margin.
  double Bound(int r0, int c0, int r1, int c1, int ir0, int ic0, int ir1, int ic1) const {
    std::uint32_t corners = 0;  // a window without a strict interior contains no group
    if (r1 - r0 >= 2 && c1 - c0 >= 2) {
      const Cell& a = cells_[Index(r0 + 1, c0 + 1)];  // integral at the interior's corners
      const Cell& b = cells_[Index(r0 + 1, c1)];
      const Cell& c = cells_[Index(r1, c0 + 1)];
      const Cell& d = cells_[Index(r1, c1)];
      corners = d.corner[0] - b.corner[0] - c.corner[0] + a.corner[0];
      for (int k = 1; k < 4; ++k) {
        corners = std::min(corners, d.corner[k] - b.corner[k] - c.corner[k] + a.corner[k]);
      }
    }
    const std::uint32_t inner = edges_[Index(ir1 + 1, ic1 + 1)] - edges_[Index(ir0, ic1 + 1)] -
                                edges_[Index(ir1 + 1, ic0)] + edges_[Index(ir0, ic0)];
    const double fixed = static_cast<double>(corners) - static_cast<double>(inner);
    return fixed * inverse_scale_ + margin_;
  }

 private:
  // Group magnitude at the four bounding-box corners: top-left, top-right, bottom-left,
  // bottom-right; one cache line fetch serves all four integrals.
  struct Cell {
    std::uint32_t corner[4] = {0, 0, 0, 0};
  };
  // Column-major (width + 1) x (height + 1): the grid walks rows innermost.
  size_t Index(int r, int c) const { return static_cast<size_t>(c) * stride_ + r; }

  size_t stride_ = 0;
  double inverse_scale_ = 0.0;  // fixed point -> magnitude
  double margin_ = 0.0;         // covers the double rounding of the exact score
  std::vector<Cell> cells_;
  std::vector<std::uint32_t> edges_;  // M where M > edge_min_mag, rounded down
};

}  // namespace tod
