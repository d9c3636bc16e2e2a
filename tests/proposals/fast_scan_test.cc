// The speed-ups of the window scan must not change a single box or score: the containment bound
// is checked against the literal score, the column scan and the threaded scan against a plain
// window-by-window loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "core/proposals/box_scorer.h"
#include "core/proposals/containment_bound.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/edge_groups.h"
#include "core/proposals/edge_orientation.h"
#include "core/proposals/window_grid.h"
#include "tests/proposals/reference_score.h"
#include "tests/proposals/test_maps.h"

namespace tod {
namespace {

EdgeGroups GroupsOf(const cv::Mat1f& map, const EdgeBoxParams& p) {
  return BuildEdgeGroups(map, ComputeEdgeOrientation(map),
                         {p.edge_min_mag, p.edge_merge_thr, p.cluster_min_mag, p.gamma});
}

TEST(ContainmentBoundTest, NeverBelowTheExactRemainderAndOftenTighterThanV) {
  const EdgeBoxParams params;
  int tighter = 0, boxes = 0;
  for (const unsigned seed : {1u, 2u, 3u}) {
    const cv::Mat1f map = testing::RandomContourMap(150, 110, seed, 6 + 6 * static_cast<int>(seed));
    const EdgeGroups groups = GroupsOf(map, params);
    ASSERT_GT(groups.count(), 10);
    const ContainmentBound bound(groups, map, params.edge_min_mag);
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> cx(0, map.cols - 1), ry(0, map.rows - 1);
    for (int trial = 0; trial < 400; ++trial) {
      int c0 = cx(rng), c1 = cx(rng), r0 = ry(rng), r1 = ry(rng);
      if (c0 > c1) std::swap(c0, c1);
      if (r0 > r1) std::swap(r0, r1);
      const int bh = (r1 - r0) / 2, bw = (c1 - c0) / 2;
      const int ir0 = r0 + bh / 2, ic0 = c0 + bw / 2;
      const double upper = bound.Bound(r0, c0, r1, c1, ir0, ic0, ir0 + bh, ic0 + bw);
      const double exact = testing::ReferenceRemainder(map, groups, r0, c0, r1, c1, params);
      ASSERT_GE(upper, exact) << c0 << "," << r0 << "," << c1 << "," << r1;
      // v alone (the early exit of Edge Boxes): anchored magnitude, before any subtraction.
      double v = 0.0;
      for (int s = 1; s <= groups.count(); ++s) {
        if (groups.anchor_x[s] >= c0 && groups.anchor_x[s] <= c1 && groups.anchor_y[s] >= r0 &&
            groups.anchor_y[s] <= r1) {
          v += groups.magnitude[s];
        }
      }
      tighter += upper < v - 0.5;
      ++boxes;
    }
  }
  EXPECT_GT(tighter, boxes / 10);  // the bound does prune beyond the plain early exit
}

TEST(ContainmentBoundTest, EnclosedContourIsCountedAndCutContourIsNot) {
  // Square outline [10, 19]^2 of value 1 (36 pixels, 36 of magnitude in some groups).
  cv::Mat1f map(40, 40, 0.f);
  testing::DrawRectangleContour(map, 10, 10, 19, 19);
  const EdgeBoxParams params;
  const EdgeGroups groups = GroupsOf(map, params);
  const ContainmentBound bound(groups, map, params.edge_min_mag);
  // Box [8, 21]^2 holds the whole outline in its interior; its centre box [11, 17]^2 holds no
  // edge. The bound is 36 up to the fixed-point rounding (ceil per group) and the margin.
  const double enclosed = bound.Bound(8, 8, 21, 21, 11, 11, 17, 17);
  EXPECT_GE(enclosed, 36.0);
  EXPECT_LT(enclosed, 36.01);
  // Box [8, 15] x [8, 21] cuts the outline at column 15: a group crossing the side is not in
  // the strict interior, so only groups entirely left of column 15 can count (< 36).
  EXPECT_LT(bound.Bound(8, 8, 21, 15, 11, 9, 17, 12), 36.0);
  // A box without a strict interior contains nothing.
  EXPECT_LE(bound.Bound(10, 10, 11, 19, 10, 12, 10, 16), 0.0 + 1e-6);
}

TEST(ContainmentBoundTest, WindowsOutsideTheInteriorTopsAllScoreZero) {
  const EdgeBoxParams params;
  const cv::Mat1f map = testing::RandomContourMap(240, 160, 4, 4);  // sparse: 4 outlines
  const EdgeGroups groups = GroupsOf(map, params);
  const ContainmentBound bound(groups, map, params.edge_min_mag);
  BoxScorer scorer(map, params);
  std::mt19937 rng(8);
  std::uniform_int_distribution<int> cx(0, map.cols - 1), size(3, 120);
  int listed = 0, skipped_windows = 0;
  std::vector<std::pair<int, int>> tops;
  for (int trial = 0; trial < 300; ++trial) {
    const int c0 = cx(rng), c1 = std::min(map.cols - 1, c0 + size(rng));
    const int h = size(rng);
    if (!bound.InteriorTops(c0, c1, h, 32, tops)) continue;
    ++listed;
    for (size_t i = 1; i < tops.size(); ++i) ASSERT_LT(tops[i - 1].second, tops[i].first);
    for (int y = 0; y + h < map.rows; ++y) {
      const bool inside = std::any_of(tops.begin(), tops.end(), [&](const auto& range) {
        return y >= range.first && y < range.second;
      });
      if (inside) continue;
      ++skipped_windows;
      ScoreWindow w{y, c0, y + h, c1, 0.f};
      scorer.Score(w);
      ASSERT_EQ(w.score, 0.f) << c0 << "," << y << "," << c1 << "," << y + h;
    }
  }
  EXPECT_GT(listed, 200);
  EXPECT_GT(skipped_windows, 5000);  // the test exercises the skip, not an empty set
  // A column with more groups than the limit is not listed.
  EXPECT_FALSE(bound.InteriorTops(0, map.cols - 1, 50, 0, tops) && groups.count() > 0);
}

// The steps InteriorTops lists sum, at every window top, to the magnitude of the groups lying
// wholly in the window's strict interior (in fixed point, each group rounded up): the exact first
// term of the containment bound, which the corner integrals only bound from above.
TEST(ContainmentBoundTest, ContainedStepsSumTheGroupsInTheStrictInterior) {
  const EdgeBoxParams params;
  const cv::Mat1f map = testing::RandomContourMap(240, 160, 6, 6);
  const EdgeGroups groups = GroupsOf(map, params);
  ASSERT_GT(groups.count(), 5);
  const ContainmentBound bound(groups, map, params.edge_min_mag);
  // Each group's bounding box, from its pixels.
  struct Extent {
    int c0 = 1 << 30, c1 = -1, r0 = 1 << 30, r1 = -1;
  };
  std::vector<Extent> extent(static_cast<size_t>(groups.count()) + 1);
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      const int s = groups.ids(r, c);
      if (s <= 0) continue;
      Extent& e = extent[s];
      e.c0 = std::min(e.c0, c), e.c1 = std::max(e.c1, c);
      e.r0 = std::min(e.r0, r), e.r1 = std::max(e.r1, r);
    }
  }
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> cx(0, map.cols - 1), size(3, 150);
  std::vector<std::pair<int, int>> tops;
  std::vector<ContainmentBound::ContainedStep> steps;
  int listed = 0, holding = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int c0 = cx(rng), c1 = std::min(map.cols - 1, c0 + size(rng));
    const int h = size(rng);
    if (!bound.InteriorTops(c0, c1, h, 32, tops, &steps)) continue;
    ++listed;
    for (size_t i = 1; i < steps.size(); ++i) ASSERT_LE(steps[i - 1].y, steps[i].y);
    std::int64_t contained = 0;
    size_t next = 0;
    for (int y = -h; y + h < map.rows; ++y) {
      for (; next < steps.size() && steps[next].y <= y; ++next) contained += steps[next].delta;
      double inside =
          0.0;  // the groups wholly in rows [y + 1, y + h - 1], columns [c0 + 1, c1 - 1]
      for (int s = 1; s <= groups.count(); ++s) {
        const Extent& e = extent[s];
        if (e.c1 >= 0 && e.c0 > c0 && e.c1 < c1 && e.r0 > y && e.r1 < y + h)
          inside += groups.magnitude[s];
      }
      holding += inside > 0.0;
      // ToMagnitude adds the rounding margin; each group's rounding up adds < 2^-24 or so.
      EXPECT_GE(bound.ToMagnitude(contained), inside) << c0 << "," << c1 << "," << y << "," << h;
      EXPECT_LE(bound.ToMagnitude(contained), inside + 1e-4) << c0 << "," << c1 << "," << y;
    }
  }
  EXPECT_GT(listed, 100);
  EXPECT_GT(holding, 1000);  // windows that hold groups, not only empty sums
}

// The plain definition: every grid window through BoxScorer::Score, refined, then NMS.
std::vector<ScoredBox> PlainScan(const cv::Mat1f& map, const EdgeBoxParams& params) {
  BoxScorer scorer(map, params);
  std::vector<ScoredBox> scored;
  for (const Box& b : GenerateWindowGrid(map.cols, map.rows, params)) {
    ScoreWindow w{b.y, b.x, b.bottom() - 1, b.right() - 1, 0.f};
    scorer.Score(w);
    if (w.score <= 0.f) continue;
    if (params.refine) scorer.Refine(w);
    scored.push_back({Box{w.c0, w.r0, w.c1 - w.c0 + 1, w.r1 - w.r0 + 1}, w.score});
  }
  return NonMaximumSuppression(scored, params.beta, params.max_boxes);
}

TEST(ScoreEdgeBoxesTest, ColumnScanAndThreadsEqualThePlainWindowLoop) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 9, 14);
  for (const float factor : {1.f, 0.5f}) {
    EdgeBoxParams params;
    params.stride_factor = factor;
    params.max_boxes = 300;  // NMS stops early: the order of the candidates matters too
    const std::vector<ScoredBox> expected = PlainScan(map, params);
    ASSERT_GT(expected.size(), 50u);
    for (const int threads : {1, 2, 3, 0}) {
      params.threads = threads;
      EdgeBoxStats stats;
      const std::vector<ScoredBox> got = ScoreEdgeBoxes(map, params, &stats);
      EXPECT_EQ(stats.windows_visited, CountWindows(map.cols, map.rows, params));
      ASSERT_EQ(got.size(), expected.size()) << factor << " threads " << threads;
      for (size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].box, expected[i].box) << factor << " threads " << threads << " " << i;
        EXPECT_EQ(got[i].score, expected[i].score);
      }
    }
  }
}

TEST(ScoreEdgeBoxesTest, ColumnScanEqualsThePlainWindowLoopOnASparseMap) {
  // Few outlines on a large map: most columns list their groups and skip the windows that
  // cannot hold one (BoxScorer::ScoreColumn); nothing may change.
  const cv::Mat1f map = testing::RandomContourMap(260, 180, 12, 3);
  EdgeBoxParams params;
  const std::vector<ScoredBox> expected = PlainScan(map, params);
  ASSERT_GT(expected.size(), 10u);
  EdgeBoxStats stats;
  const std::vector<ScoredBox> got = ScoreEdgeBoxes(map, params, &stats);
  EXPECT_EQ(stats.windows_visited, CountWindows(map.cols, map.rows, params));
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].box, expected[i].box) << i;
    EXPECT_EQ(got[i].score, expected[i].score) << i;
  }
}

TEST(ScoreEdgeBoxesTest, NegativeThreadCountIsRejected) {
  EdgeBoxParams params;
  params.threads = -1;
  const Status s = ValidateEdgeBoxParams(params);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("threads"), std::string::npos);
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

TEST(ScoreEdgeBoxesTest, RefineLimitIsExactWhenItCoversEveryWindowAndCutsWorkBelow) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 4, 14);
  EdgeBoxParams params;
  EdgeBoxStats exact_stats, limited_stats, plain_stats;
  const auto exact = ScoreEdgeBoxes(map, params, &exact_stats);
  ASSERT_GT(exact_stats.windows_nonzero, 20);
  // A limit at the number of refinable windows refines them all: the exact result.
  params.refine_limit = static_cast<int>(exact_stats.windows_nonzero);
  const auto covered = ScoreEdgeBoxes(map, params);
  ASSERT_EQ(covered.size(), exact.size());
  for (size_t i = 0; i < exact.size(); ++i) {
    EXPECT_EQ(covered[i].box, exact[i].box);
    EXPECT_EQ(covered[i].score, exact[i].score);
  }
  // Refining only the best grid window: fewer walks than refining all, more than none, and the
  // best box is at least as good as without refinement.
  params.refine_limit = 1;
  const auto limited = ScoreEdgeBoxes(map, params, &limited_stats);
  params.refine = false;
  const auto plain = ScoreEdgeBoxes(map, params, &plain_stats);
  EXPECT_LT(limited_stats.scorings, exact_stats.scorings);
  EXPECT_GT(limited_stats.scorings, plain_stats.scorings);
  ASSERT_FALSE(limited.empty());
  EXPECT_GE(limited[0].score, plain[0].score);
  params = EdgeBoxParams{};
  params.refine_limit = -2;
  EXPECT_NE(ValidateEdgeBoxParams(params).message().find("refine_limit"), std::string::npos);
}

}  // namespace
}  // namespace tod
