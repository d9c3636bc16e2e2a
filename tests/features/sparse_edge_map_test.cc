#include "core/features/sparse_edge_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

namespace tod {
namespace {

// The original definition, pixel by pixel in the original order (64-column bands left to right,
// rows top to bottom, columns ascending): the double sums must match it bit for bit.
BoxEdgeStats Reference(const cv::Mat1f& map, const cv::Rect& box, const cv::Rect& inner) {
  BoxEdgeStats s;
  std::map<float, int> counts;
  const int x1 = box.x + box.width;
  for (int band = box.x >> 6; band <= (x1 - 1) >> 6; ++band) {
    for (int y = box.y; y < box.y + box.height; ++y) {
      for (int x = std::max(box.x, band << 6); x < std::min(x1, (band + 1) << 6); ++x) {
        const float v = map(y, x);
        if (v == 0.f) continue;
        const bool in_inner = inner.contains({x, y});
        s.sum += v;
        if (in_inner) s.inner_sum += v;
        if (v > 0.f) {
          ++s.count;
          ++counts[v];
          if (in_inner) ++s.inner_count;
        }
      }
    }
  }
  for (const auto& [value, n] : counts) {  // ascending: the smallest value wins ties
    if (n > s.mode_count) s.mode_count = n, s.mode_value = value;
    s.max_value = value;
  }
  return s;
}

// Boundary-like map: horizontal and vertical segments of one random value each (some negative),
// drawn from `levels` so that values repeat across segments.
cv::Mat1f SegmentMap(int rows, int cols, const std::vector<float>& levels, cv::RNG& rng) {
  cv::Mat1f map(rows, cols, 0.f);
  for (int s = 0; s < rows * cols / 40; ++s) {
    const float v = levels[rng.uniform(0, static_cast<int>(levels.size()))];
    const int length = rng.uniform(1, 25);
    const int x = rng.uniform(0, cols), y = rng.uniform(0, rows);
    for (int i = 0; i < length; ++i) {
      if (rng.uniform(0, 2) == 0) {
        if (x + i < cols) map(y, x + i) = v;
      } else if (y + i < rows) {
        map(y + i, x) = v;
      }
    }
  }
  return map;
}

void ExpectSameStats(const cv::Mat1f& map, int trials, cv::RNG& rng) {
  const Result<SparseEdgeMap> edges = SparseEdgeMap::Build(map);
  ASSERT_TRUE(edges.ok());
  for (int trial = 0; trial < trials; ++trial) {
    const int w = rng.uniform(1, map.cols + 1), h = rng.uniform(1, map.rows + 1);
    const cv::Rect box(rng.uniform(0, map.cols - w + 1), rng.uniform(0, map.rows - h + 1), w, h);
    const cv::Rect inner(box.x + (w - w / 2) / 2, box.y + (h - h / 2) / 2, w / 2, h / 2);
    const BoxEdgeStats got = edges->Measure(box, inner);
    const BoxEdgeStats want = Reference(map, box, inner);
    ASSERT_EQ(got.max_value, want.max_value) << "trial " << trial;
    ASSERT_EQ(got.mode_value, want.mode_value) << "trial " << trial;
    ASSERT_EQ(got.mode_count, want.mode_count) << "trial " << trial;
    ASSERT_EQ(got.count, want.count) << "trial " << trial;
    ASSERT_EQ(got.inner_count, want.inner_count) << "trial " << trial;
    // Bitwise: the sums must not depend on how they are computed.
    ASSERT_EQ(got.sum, want.sum) << "trial " << trial;
    ASSERT_EQ(got.inner_sum, want.inner_sum) << "trial " << trial;
  }
}

TEST(SparseEdgeMapTest, MatchesOriginalOrderBitForBit) {
  // Arbitrary floats in the range of occlusion strengths: the exact integer sums apply.
  cv::RNG rng(77);
  std::vector<float> levels;
  for (int i = 0; i < 40; ++i) levels.push_back(static_cast<float>(rng.uniform(0.01, 1.0)));
  levels.push_back(-0.37f);
  levels.push_back(-1e-3f);
  ExpectSameStats(SegmentMap(90, 300, levels, rng), 400, rng);
}

TEST(SparseEdgeMapTest, WideDynamicRangeFallsBackToTheOriginalOrder) {
  // Values 2^-60 .. 2^60 apart: the sums round, so only the original order reproduces them.
  cv::RNG rng(78);
  const std::vector<float> levels = {1e-18f, 3.3e-7f, 0.1f, 0.7f, 1.3f, 7e5f, 1.1e18f, -2.9e17f};
  ExpectSameStats(SegmentMap(70, 260, levels, rng), 400, rng);
}

TEST(SparseEdgeMapTest, EmptyAndAllZeroMaps) {
  const Result<SparseEdgeMap> zeros = SparseEdgeMap::Build(cv::Mat1f(5, 7, 0.f));
  ASSERT_TRUE(zeros.ok());
  const BoxEdgeStats s = zeros->Measure({0, 0, 7, 5}, {2, 1, 3, 2});
  EXPECT_EQ(s.count, 0);
  EXPECT_EQ(s.sum, 0.0);
  EXPECT_FALSE(std::signbit(s.sum));
  EXPECT_EQ(s.mode_value, 0.f);
  const Result<SparseEdgeMap> empty = SparseEdgeMap::Build(cv::Mat1f());
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(empty->size(), cv::Size(0, 0));
}

}  // namespace
}  // namespace tod
