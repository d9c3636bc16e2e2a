// The per-map tables are built from edge-pixel lists and with orientation computed at edge pixels
// only; these tests pin that every sparse path is bit-identical to the dense one it replaces.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/proposals/box_scorer.h"
#include "core/proposals/containment_bound.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/edge_groups.h"
#include "core/proposals/edge_orientation.h"
#include "tests/proposals/test_maps.h"

namespace tod {
namespace {

// Random values in [0, 1] on a fraction `density` of the pixels.
cv::Mat1f SparseNoise(int width, int height, float density, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  cv::Mat1f map(height, width, 0.f);
  for (float& v : map) {
    if (u(rng) < density) v = u(rng);
  }
  return map;
}

template <typename T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(SparseTablesTest, OrientationAtMatchesTheDenseMapEverywhere) {
  const int sizes[][2] = {{1, 1}, {2, 2}, {1, 9}, {9, 1}, {2, 7}, {7, 2}, {3, 3}, {37, 23}};
  unsigned seed = 1;
  for (const auto& [w, h] : sizes) {
    const cv::Mat1f map = SparseNoise(w, h, 0.3f, seed++);
    const cv::Mat1f dense = ComputeEdgeOrientation(map);
    const cv::Mat1f smoothed = SmoothForOrientation(map);
    for (int r = 0; r < h; ++r) {
      for (int c = 0; c < w; ++c) {
        EXPECT_TRUE(SameBits(OrientationAt(smoothed, r, c), dense(r, c)))
            << w << "x" << h << " at " << r << "," << c;
      }
    }
  }
}

TEST(SparseTablesTest, EdgePixelListsMatchAPlainScan) {
  cv::Mat1f map = SparseNoise(53, 31, 0.2f, 7);  // width not a multiple of the scan block
  map(3, 4) = std::numeric_limits<float>::quiet_NaN();
  map(5, 20) = std::numeric_limits<float>::infinity();
  const float min_magnitude = 0.1f;
  const EdgePixels e = FindEdgePixels(map, min_magnitude);
  ASSERT_EQ(e.rows, map.rows);
  ASSERT_EQ(e.cols, map.cols);
  std::vector<int> row_col, col_row;
  std::vector<float> row_value, col_value;
  for (int r = 0; r < map.rows; ++r) {
    EXPECT_EQ(e.row_begin[r], static_cast<int>(row_col.size()));
    for (int c = 0; c < map.cols; ++c) {
      if (map(r, c) > min_magnitude) {
        row_col.push_back(c);
        row_value.push_back(map(r, c));
      }
    }
  }
  for (int c = 0; c < map.cols; ++c) {
    EXPECT_EQ(e.col_begin[c], static_cast<int>(col_row.size()));
    for (int r = 0; r < map.rows; ++r) {
      if (map(r, c) > min_magnitude) {
        col_row.push_back(r);
        col_value.push_back(map(r, c));
      }
    }
  }
  EXPECT_EQ(e.row_col, row_col);
  EXPECT_EQ(e.col_row, col_row);
  EXPECT_TRUE(SameBits(e.row_value, row_value));
  EXPECT_TRUE(SameBits(e.col_value, col_value));
}

TEST(SparseTablesTest, GroupsWithSparseOrientationEqualTheDenseOnes) {
  for (const unsigned seed : {1u, 2u, 3u, 4u}) {
    const cv::Mat1f map = testing::RandomContourMap(160, 120, seed, 10 * static_cast<int>(seed));
    for (const float cluster_min_mag : {0.f, 0.5f, 3.f}) {
      EdgeGroupParams params;
      params.cluster_min_mag = cluster_min_mag;
      const EdgeGroups dense = BuildEdgeGroups(map, ComputeEdgeOrientation(map), params);
      const EdgeGroups sparse = BuildEdgeGroups(map, params);
      ASSERT_GT(dense.count(), 5);
      EXPECT_EQ(cv::countNonZero(dense.ids != sparse.ids), 0);
      EXPECT_TRUE(SameBits(dense.magnitude, sparse.magnitude));
      EXPECT_TRUE(SameBits(dense.mean_x, sparse.mean_x));
      EXPECT_TRUE(SameBits(dense.mean_y, sparse.mean_y));
      EXPECT_TRUE(SameBits(dense.orientation, sparse.orientation));
      EXPECT_EQ(dense.anchor_x, sparse.anchor_x);
      EXPECT_EQ(dense.anchor_y, sparse.anchor_y);
      EXPECT_EQ(dense.affinity_begin, sparse.affinity_begin);
      EXPECT_EQ(dense.affinity_target, sparse.affinity_target);
      EXPECT_TRUE(SameBits(dense.affinity_value, sparse.affinity_value));
      EXPECT_EQ(
          cv::countNonZero(GroupEdgePixels(map, ComputeEdgeOrientation(map), params) != sparse.ids),
          0);
    }
  }
}

TEST(SparseTablesTest, BoundFromEdgeListsEqualsBoundFromTheMap) {
  const EdgeBoxParams p;
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 9, 25);
  const EdgeGroups groups =
      BuildEdgeGroups(map, {p.edge_min_mag, p.edge_merge_thr, p.cluster_min_mag, p.gamma});
  const ContainmentBound from_map(groups, map, p.edge_min_mag);
  const ContainmentBound from_lists(groups, groups.edges);
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> x(0, map.cols - 1), y(0, map.rows - 1);
  for (int i = 0; i < 2000; ++i) {
    int c0 = x(rng), c1 = x(rng), r0 = y(rng), r1 = y(rng);
    if (c0 > c1) std::swap(c0, c1);
    if (r0 > r1) std::swap(r0, r1);
    const int ir0 = r0 + (r1 - r0) / 4, ic0 = c0 + (c1 - c0) / 4;
    const int ir1 = ir0 + (r1 - r0) / 2, ic1 = ic0 + (c1 - c0) / 2;
    EXPECT_EQ(from_map.Bound(r0, c0, r1, c1, ir0, ic0, ir1, ic1),
              from_lists.Bound(r0, c0, r1, c1, ir0, ic0, ir1, ic1));
  }
}

// The scorer uses a finite, non-view map as it is and copies the others: a view must score as
// its own copy (the orientation smoothing must not see the parent's pixels), and non-finite
// values as zeros.
TEST(SparseTablesTest, ViewsAndNonFiniteMapsScoreAsTheirCleanCopies) {
  const EdgeBoxParams params;
  const cv::Mat1f parent = testing::RandomContourMap(220, 160, 5, 40);
  const cv::Mat1f view = parent(cv::Rect(17, 9, 150, 120));
  cv::Mat1f with_nan = view.clone();
  cv::Mat1f zeroed = view.clone();
  for (int i = 0; i < 30; ++i) {
    const int r = (i * 37) % with_nan.rows, c = (i * 53) % with_nan.cols;
    with_nan(r, c) = i % 2 == 0 ? std::numeric_limits<float>::quiet_NaN()
                                : std::numeric_limits<float>::infinity();
    zeroed(r, c) = 0.f;
  }
  BoxScorer from_view(view, params), from_copy(view.clone(), params);
  BoxScorer from_nan(with_nan, params), from_zeroed(zeroed, params);
  EXPECT_EQ(cv::countNonZero(from_view.groups().ids != from_copy.groups().ids), 0);
  std::mt19937 rng(2);
  std::uniform_int_distribution<int> x(0, view.cols - 1), y(0, view.rows - 1), side(3, 80);
  for (int i = 0; i < 3000; ++i) {
    ScoreWindow w;
    w.c0 = x(rng);
    w.r0 = y(rng);
    w.c1 = w.c0 + side(rng);
    w.r1 = w.r0 + side(rng);
    ScoreWindow a = w, b = w, c = w, d = w;
    from_view.Score(a);
    from_copy.Score(b);
    from_nan.Score(c);
    from_zeroed.Score(d);
    EXPECT_TRUE(SameBits(a.score, b.score));
    EXPECT_TRUE(SameBits(c.score, d.score));
  }
}

}  // namespace
}  // namespace tod
