// EdgeBoxParams::deadline (the frame budget): a deadline that is never reached changes nothing,
// even though the column chunks are then handed out in a scattered order; a passed one stops
// the scan and says so.
#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/window_grid.h"
#include "tests/proposals/test_maps.h"

namespace tod {
namespace {

using Clock = std::chrono::steady_clock;

TEST(ScanDeadlineTest, ADistantDeadlineGivesExactlyTheUnlimitedResult) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 9, 14);
  EdgeBoxParams params;
  params.max_boxes = 300;
  const std::vector<ScoredBox> expected = ScoreEdgeBoxes(map, params);
  ASSERT_GT(expected.size(), 50u);
  for (const int threads : {1, 2}) {
    params.threads = threads;
    params.deadline = Clock::now() + std::chrono::hours(1);
    EdgeBoxStats stats;
    const std::vector<ScoredBox> got = ScoreEdgeBoxes(map, params, &stats);
    EXPECT_FALSE(stats.truncated);
    EXPECT_EQ(stats.columns_skipped, 0);
    EXPECT_EQ(stats.windows_visited, CountWindows(map.cols, map.rows, params));
    ASSERT_EQ(got.size(), expected.size()) << "threads " << threads;
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].box, expected[i].box) << i;
      EXPECT_EQ(got[i].score, expected[i].score) << i;
    }
  }
}

TEST(ScanDeadlineTest, APassedDeadlineScansNothingAndSaysSo) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 9, 14);
  EdgeBoxParams params;
  params.deadline = Clock::now() - std::chrono::milliseconds(1);
  EdgeBoxStats stats;
  const std::vector<ScoredBox> got = ScoreEdgeBoxes(map, params, &stats);
  EXPECT_TRUE(got.empty());
  EXPECT_TRUE(stats.truncated);
  EXPECT_EQ(stats.windows_visited, 0);
  EXPECT_GT(stats.columns_skipped, 0);
}

}  // namespace
}  // namespace tod
