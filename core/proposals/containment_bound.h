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

#include <algorithm>
#include <cstdint>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "core/proposals/edge_groups.h"

namespace tod {

class ContainmentBound {
 public:
  ContainmentBound() = default;
  // edge_map: finite values; edge pixels are those > edge_min_mag (as in the score).
  ContainmentBound(const EdgeGroups& groups, const cv::Mat1f& edge_map, float edge_min_mag);
  // The same from the map's edge pixels (groups.edges when the threshold is the score's).
  ContainmentBound(const EdgeGroups& groups, const EdgePixels& edges);

  // Group magnitude at the four bounding-box corners: top-left, top-right, bottom-left,
  // bottom-right; one cache line fetch serves all four integrals.
  struct Cell {
    std::uint32_t corner[4] = {0, 0, 0, 0};
  };

  // The integral-image columns one grid column of windows reads: computed once per column so
  // that the per-window bound is a few loads.
  struct Columns {
    const Cell* left = nullptr;   // interior's first column
    const Cell* right = nullptr;  // one past the interior's last column
    const std::uint32_t* inner_left = nullptr;
    const std::uint32_t* inner_right = nullptr;
    bool has_interior = false;
  };
  // For windows spanning columns [c0, c1] with centre-box columns [ic0, ic1].
  Columns ColumnsOf(int c0, int c1, int ic0, int ic1) const {
    Columns v;
    v.has_interior = c1 - c0 >= 2;
    if (v.has_interior) {
      v.left = &cells_[Index(0, c0 + 1)];
      v.right = &cells_[Index(0, c1)];
    }
    v.inner_left = &edges_[Index(0, ic0)];
    v.inner_right = &edges_[Index(0, ic1 + 1)];
    return v;
  }

  // The bound in fixed-point units (corner minimum - centre-box edges) of the clamped inclusive
  // window [r0, r1] x [c0, c1] whose centre box is [ir0, ir1] x [ic0, ic1] (columns as given to
  // ColumnsOf). Monotone: ToMagnitude() turns it into the bound on v - removed.
  std::int64_t FixedBound(const Columns& v, int r0, int r1, int ir0, int ir1) const {
    std::uint32_t corners = 0;  // a window without a strict interior contains no group
    if (v.has_interior && r1 - r0 >= 2) {
      const Cell& a = v.left[r0 + 1];  // the integrals at the interior's four corners
      const Cell& b = v.right[r0 + 1];
      const Cell& c = v.left[r1];
      const Cell& d = v.right[r1];
      corners = d.corner[0] - b.corner[0] - c.corner[0] + a.corner[0];
      for (int k = 1; k < 4; ++k) {
        corners = std::min(corners, d.corner[k] - b.corner[k] - c.corner[k] + a.corner[k]);
      }
    }
    return static_cast<std::int64_t>(corners) - InnerEdges(v, ir0, ir1);
  }
  // FixedBound(...) >= threshold, cheapest test first: most windows fail on one corner sum.
  bool Reaches(const Columns& v, int r0, int r1, int ir0, int ir1, std::int64_t threshold) const {
    if (!v.has_interior || r1 - r0 < 2) return -InnerEdges(v, ir0, ir1) >= threshold;
    const Cell& a = v.left[r0 + 1];
    const Cell& b = v.right[r0 + 1];
    const Cell& c = v.left[r1];
    const Cell& d = v.right[r1];
    // Centre-box edges are >= 0, so a corner sum below the threshold already decides.
    if (static_cast<std::int64_t>(d.corner[0] - b.corner[0] - c.corner[0] + a.corner[0]) <
        threshold) {
      return false;
    }
    const std::int64_t needed = threshold + InnerEdges(v, ir0, ir1);
    for (int k = 0; k < 4; ++k) {
      if (static_cast<std::int64_t>(d.corner[k] - b.corner[k] - c.corner[k] + a.corner[k]) <
          needed) {
        return false;
      }
    }
    return true;
  }
  // The tops y of a column's windows (rows [y, y + box_height], columns [c0, c1]) whose strict
  // interior holds a whole group, as sorted disjoint [begin, end) ranges in `tops`. Only those
  // windows can score above 0: by the argument above, every group anchored inside a window
  // that is not wholly in its interior touches a side, gets weight 1 and is removed, so
  // v - removed <= -(centre-box edges) <= 0 without one. Sparse maps leave most of a column
  // without such a window, and listing the few groups in the columns is cheaper than testing
  // every window. Returns false (tops unspecified) when more than max_groups groups start in
  // the interior's columns: then listing them would cost more than the scan it saves.
  //
  // With `steps`, also the exact fixed-point magnitude of the groups a window's strict interior
  // holds, as steps over the window top (sorted by y): the window at top y holds the sum of the
  // deltas of the steps at or before y. That sum is the first term of the bound without the
  // corners' over-count (FixedBound takes the least of four sums that each count groups sticking
  // out elsewhere), so ContainedReaches rejects more windows than Reaches, every one of which the
  // walk would have found hopeless (docs/findings.md#the-walks-tables).
  struct ContainedStep {
    int y = 0;
    std::int64_t delta = 0;
  };
  bool InteriorTops(int c0, int c1, int box_height, int max_groups,
                    std::vector<std::pair<int, int>>& tops,
                    std::vector<ContainedStep>* steps = nullptr) const;
  // Reaches() for a window whose strict interior holds groups of fixed-point magnitude
  // `contained` (summed from InteriorTops' steps).
  bool ContainedReaches(const Columns& v, std::int64_t contained, int ir0, int ir1,
                        std::int64_t threshold) const {
    return contained - InnerEdges(v, ir0, ir1) >= threshold;
  }

  double ToMagnitude(std::int64_t fixed) const {
    return static_cast<double>(fixed) * inverse_scale_ + margin_;
  }
  // The smallest fixed-point value whose magnitude a monotone test `hopeless` (true for small
  // values) accepts, so that a hot loop can compare integers; kNever when none up to 2^32 does.
  static constexpr std::int64_t kNever = std::int64_t{1} << 40;
  template <typename Hopeless>
  std::int64_t SmallestHopeful(Hopeless hopeless) const {
    std::int64_t lo = -(std::int64_t{1} << 33), hi = std::int64_t{1} << 33;
    if (!hopeless(ToMagnitude(lo))) return lo;
    if (hopeless(ToMagnitude(hi))) return kNever;
    while (hi - lo > 1) {  // hopeless(lo) and !hopeless(hi)
      const std::int64_t mid = lo + (hi - lo) / 2;
      (hopeless(ToMagnitude(mid)) ? lo : hi) = mid;
    }
    return hi;
  }

  // Upper bound on v - removed (magnitude units, with the rounding margin).
  double Bound(const Columns& v, int r0, int r1, int ir0, int ir1) const {
    return ToMagnitude(FixedBound(v, r0, r1, ir0, ir1));
  }
  double Bound(int r0, int c0, int r1, int c1, int ir0, int ic0, int ir1, int ic1) const {
    return Bound(ColumnsOf(c0, c1, ic0, ic1), r0, r1, ir0, ir1);
  }

 private:
  // Column-major (width + 1) x (height + 1): the grid walks rows innermost.
  size_t Index(int r, int c) const { return static_cast<size_t>(c) * stride_ + r; }
  std::int64_t InnerEdges(const Columns& v, int ir0, int ir1) const {
    return v.inner_right[ir1 + 1] - v.inner_right[ir0] - v.inner_left[ir1 + 1] + v.inner_left[ir0];
  }

  // A group's bounding box (inclusive) and its magnitude in fixed point, rounded up.
  struct GroupBox {
    int c0 = 0, c1 = 0, r0 = 0, r1 = 0;
    std::uint32_t magnitude = 0;
  };
  // The constructor's steps. Per group id (0 unused), its bounding box; c1 < 0 for a group
  // without pixels.
  static std::vector<GroupBox> GroupExtents(const EdgeGroups& groups, const EdgePixels& edges);
  // cells_: the groups' fixed-point magnitudes (GroupBox::magnitude of `extents`, indexed by
  // group id) summed at their four corners.
  void BuildCornerIntegral(const EdgeGroups& groups, const std::vector<GroupBox>& extents,
                           int width, int height);
  // edges_: the edge pixels' magnitudes (times `scale`, rounded down).
  void BuildEdgeIntegral(const EdgePixels& edges, double scale, int width, int height);

  size_t stride_ = 0;
  double inverse_scale_ = 0.0;  // fixed point -> magnitude
  double margin_ = 0.0;         // covers the double rounding of the exact score
  std::vector<Cell> cells_;
  std::vector<std::uint32_t> edges_;   // M where M > edge_min_mag, rounded down
  std::vector<GroupBox> group_boxes_;  // the groups with pixels, by first column
};

}  // namespace tod
