// The two ways the scan saves work (ALGORITHM.md §4.2.7, §4.3): windows the size filter must
// reject whatever refinement does are not scored, and optionally only the grid's local maxima
// are refined.
#include "core/proposals/window_admission.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/proposals/box_scorer.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/refinement_schedule.h"
#include "core/proposals/window_grid.h"
#include "tests/proposals/test_maps.h"

namespace tod {
namespace {

constexpr float kRatio = (1.f - 0.65f) / (1.f + 0.65f);

TEST(RefinementScheduleTest, StepsHalveFromTheSpanAndStopAtTwo) {
  // span 100: floor(100 * 0.2121) = 21 -> 10, 5, then 2 stops.
  const RefinementSchedule s = ScheduleRefinement(100, 100, kRatio);
  ASSERT_EQ(s.count, 2);
  EXPECT_EQ(s.row_step[0], 10);
  EXPECT_EQ(s.row_step[1], 5);
  EXPECT_EQ(s.row_reach, 15);
  // Small windows are not refined at all; a long thin one moves its short sides by 1 px steps.
  EXPECT_EQ(ScheduleRefinement(10, 10, kRatio).count, 0);
  const RefinementSchedule thin = ScheduleRefinement(8, 200, kRatio);
  ASSERT_GT(thin.count, 0);
  EXPECT_EQ(thin.row_step[0], 1);
  EXPECT_EQ(thin.row_reach, thin.count);
}

TEST(RefinementScheduleTest, RefinedSidesStayWithinTheReach) {
  const cv::Mat1f map = testing::RandomContourMap(160, 120, 5, 14);
  const EdgeBoxParams params;
  BoxScorer scorer(map, params);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> x(0, 100), y(0, 70), side(12, 60);
  int moved = 0;
  for (int i = 0; i < 400; ++i) {
    ScoreWindow w{y(rng), x(rng), 0, 0, 0.f};
    w.r1 = std::min(w.r0 + side(rng), map.rows - 1);
    w.c1 = std::min(w.c0 + side(rng), map.cols - 1);
    scorer.Score(w);
    if (w.score <= 0.f) continue;
    const ScoreWindow start = w;
    const RefinementSchedule s = ScheduleRefinement(w.r1 - w.r0, w.c1 - w.c0, kRatio);
    scorer.Refine(w);
    moved += w.r0 != start.r0 || w.c0 != start.c0 || w.r1 != start.r1 || w.c1 != start.c1;
    EXPECT_LE(std::abs(w.r0 - start.r0), s.row_reach);
    EXPECT_LE(std::abs(w.r1 - start.r1), s.row_reach);
    EXPECT_LE(std::abs(w.c0 - start.c0), s.col_reach);
    EXPECT_LE(std::abs(w.c1 - start.c1), s.col_reach);
  }
  EXPECT_GT(moved, 10);  // the bound was exercised by windows that did move
}

SizeFilter OneBand() {
  SizeFilter f;
  // Centre rows (50, 80) of the image, boxes 10..20 px on each side, area 100..400.
  f.bands.push_back(SizeBand{50, 80, 10, 20, 10, 20, 100, 400});
  return f;
}

bool Covers(const RowRanges& ranges, int top) {
  for (const auto& [begin, end] : ranges)
    if (top >= begin && top < end) return true;
  return false;
}

TEST(WindowAdmissionTest, AdmitsExactlyTheTopsWhoseCentreCanFallInABand) {
  const WindowAdmission admission(OneBand(), /*origin_y=*/30);
  // A 15 x 15 window that refinement cannot move: centre row 30 + t + 7.5 in (50, 80), so
  // t in (12.5, 42.5); one row of slack either side is allowed.
  const RowRanges tops = admission.AdmittedTops(15, 15, {}, 200);
  for (int t = 13; t <= 42; ++t) EXPECT_TRUE(Covers(tops, t)) << t;
  for (const int t : {0, 5, 10, 46, 60, 150}) EXPECT_FALSE(Covers(tops, t)) << t;
  // Refinement that can move each side by 5 rows widens the range by 5 on each side.
  const RowRanges reach = admission.AdmittedTops(15, 15, {5, 0}, 200);
  for (int t = 8; t <= 47; ++t) EXPECT_TRUE(Covers(reach, t)) << t;
  // Too tall for the band, unless refinement can shrink it enough.
  EXPECT_TRUE(admission.AdmittedTops(15, 40, {}, 200).empty());
  EXPECT_FALSE(admission.AdmittedTops(15, 40, {10, 0}, 200).empty());
  // Too small in area (5 x 5 = 25 < 100) however placed.
  EXPECT_TRUE(admission.AdmittedTops(5, 5, {}, 200).empty());
  // A disabled filter admits every top.
  SizeFilter off = OneBand();
  off.enabled = false;
  EXPECT_EQ(WindowAdmission(off, 30).AdmittedTops(500, 500, {}, 77), (RowRanges{{0, 77}}));
}

// Boxes of one scan that pass `filter`, region rows offset by origin_y.
std::vector<ScoredBox> Kept(const std::vector<ScoredBox>& boxes, const SizeFilter& filter,
                            int origin_y) {
  std::vector<ScoredBox> kept;
  for (ScoredBox b : boxes) {
    b.box.y += origin_y;
    if (filter.Keep(b.box)) kept.push_back(b);
  }
  return kept;
}

TEST(WindowAdmissionTest, TheScanKeepsEveryBoxTheFilterKeepsAndScoresFewerWindows) {
  const cv::Mat1f map = testing::RandomContourMap(200, 140, 8, 24);
  SizeFilter filter;
  filter.bands.push_back(SizeBand{110, 160, 8, 30, 8, 40, 80, 900});
  filter.bands.push_back(SizeBand{159, 230, 20, 60, 20, 70, 400, 3000});
  const int origin_y = 90;
  EdgeBoxParams params;
  params.refine_local_maxima = false;  // every scoring window refined: the comparison is exact
  params.beta = 1.f;                   // no suppression, no cut: every scored box is compared
  params.max_boxes = 1 << 30;
  EdgeBoxStats all_stats, admitted_stats;
  const std::vector<ScoredBox> all =
      Kept(ScoreEdgeBoxes(map, params, &all_stats), filter, origin_y);
  const WindowAdmission admission(filter, origin_y);
  const std::vector<ScoredBox> admitted =
      Kept(ScoreEdgeBoxes(map, params, &admitted_stats, &admission), filter, origin_y);
  ASSERT_GT(all.size(), 20u);
  ASSERT_EQ(admitted.size(), all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(admitted[i].box, all[i].box) << i;
    EXPECT_EQ(admitted[i].score, all[i].score) << i;
  }
  EXPECT_LT(admitted_stats.windows_visited, all_stats.windows_visited / 2);
  EXPECT_LT(admitted_stats.scorings, all_stats.scorings);
}

// Grid scores of one window shape, [column][row], computed one window at a time.
std::vector<std::vector<float>> ShapeScores(BoxScorer& scorer, const WindowShape& shape) {
  std::vector<std::vector<float>> scores;
  for (int x = 0; x < scorer.width() - shape.width + shape.stride_x; x += shape.stride_x) {
    scores.emplace_back();
    for (int y = 0; y < scorer.height() - shape.height + shape.stride_y; y += shape.stride_y) {
      ScoreWindow w{y, x, y + shape.height, x + shape.width, 0.f};
      scorer.Score(w);
      scores.back().push_back(w.score);
    }
  }
  return scores;
}

TEST(RefineLocalMaximaTest, RefinesExactlyTheGridLocalMaximaAndImprovesOnTheGrid) {
  const cv::Mat1f map = testing::RandomContourMap(150, 110, 2, 16);
  EdgeBoxParams params;
  params.refine_local_maxima = true;
  // Count the local maxima independently: a non-zero window no 8-neighbour of its shape beats.
  BoxScorer scorer(map, params);
  long long maxima = 0, nonzero = 0;
  for (const WindowShape& shape : WindowShapes(map.cols, map.rows, params)) {
    const auto s = ShapeScores(scorer, shape);
    for (size_t c = 0; c < s.size(); ++c) {
      for (size_t r = 0; r < s[c].size(); ++r) {
        if (s[c][r] <= 0.f) continue;
        ++nonzero;
        bool best = true;
        for (int dc = -1; dc <= 1; ++dc) {
          for (int dr = -1; dr <= 1; ++dr) {
            const long long cc = static_cast<long long>(c) + dc,
                            rr = static_cast<long long>(r) + dr;
            if (cc < 0 || rr < 0 || cc >= static_cast<long long>(s.size()) ||
                rr >= static_cast<long long>(s[cc].size()))
              continue;
            best = best && s[cc][rr] <= s[c][r];
          }
        }
        maxima += best;
      }
    }
  }
  EdgeBoxStats stats, all_stats;
  const std::vector<ScoredBox> local = ScoreEdgeBoxes(map, params, &stats);
  EXPECT_EQ(stats.windows_nonzero, nonzero);
  EXPECT_EQ(stats.windows_refined, maxima);
  EXPECT_LT(maxima * 2, nonzero);  // most scoring windows have a better neighbour
  // refine_limit then takes the best of the maxima.
  EdgeBoxParams limited = params;
  limited.refine_limit = 5;
  EdgeBoxStats limited_stats;
  ScoreEdgeBoxes(map, limited, &limited_stats);
  EXPECT_EQ(limited_stats.windows_refined, 5);
  params.refine_local_maxima = false;
  const std::vector<ScoredBox> all = ScoreEdgeBoxes(map, params, &all_stats);
  EXPECT_LT(stats.scorings, all_stats.scorings);
  // Refining the maxima improves on the grid, and comes close to refining everything (a
  // non-maximal window can climb to a better box: it is an approximation).
  params.refine = false;
  const std::vector<ScoredBox> grid = ScoreEdgeBoxes(map, params);
  ASSERT_FALSE(local.empty());
  EXPECT_GT(local[0].score, grid[0].score);
  EXPECT_GT(local[0].score, 0.9f * all[0].score);
}

}  // namespace
}  // namespace tod
