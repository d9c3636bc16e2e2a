// The provisional scan of ScanWindowGrid (a first scan keeping only windows above a score bar)
// must give exactly the boxes of the plain scan: when it settles (NMS fills max_boxes, enough
// local maxima remain), and when it does not and the grid is scanned again.
#include <gtest/gtest.h>

#include <vector>

#include "core/proposals/box_scorer.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/window_scan.h"
#include "tests/proposals/test_maps.h"

namespace tod {
namespace {

struct Scan {
  std::vector<ScoredBox> boxes;
  EdgeBoxStats stats;
};

Scan ScanGrid(const cv::Mat1f& map, const EdgeBoxParams& params, float provisional_bar) {
  const BoxScorer scorer(map, params);
  Scan scan;
  scan.boxes = ScanWindowGrid(scorer, params, scan.stats, nullptr, provisional_bar);
  return scan;
}

void ExpectSameBoxes(const std::vector<ScoredBox>& a, const std::vector<ScoredBox>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].box, b[i].box) << i;
    EXPECT_EQ(a[i].score, b[i].score) << i;
  }
}

EdgeBoxParams LimitedRefinement(int max_boxes) {
  EdgeBoxParams params;
  params.refine_local_maxima = true;
  params.refine_limit = 3;
  params.max_boxes = max_boxes;
  return params;
}

TEST(ProvisionalBarTest, SettledScanIsExactWithFewerWalks) {
  for (const int seed : {4, 8, 9}) {
    const cv::Mat1f map = testing::RandomContourMap(140, 100, static_cast<unsigned>(seed), 14);
    const EdgeBoxParams params = LimitedRefinement(6);
    const Scan plain = ScanGrid(map, params, 0.f);
    const Scan barred = ScanGrid(map, params, kProvisionalBar);
    ASSERT_EQ(plain.boxes.size(), 6u) << "the test needs a grid that fills max_boxes";
    EXPECT_EQ(barred.stats.rescans, 0) << seed;
    EXPECT_LT(barred.stats.scorings, plain.stats.scorings) << seed;
    ExpectSameBoxes(barred.boxes, plain.boxes);
  }
}

TEST(ProvisionalBarTest, UnsettledScanIsRepeatedWithoutTheBar) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 4, 14);
  const EdgeBoxParams params = LimitedRefinement(6);
  const Scan plain = ScanGrid(map, params, 0.f);
  // No window scores above 1000 x min_score: NMS cannot fill up, so the grid is scanned again.
  const Scan barred = ScanGrid(map, params, 1000.f);
  EXPECT_EQ(barred.stats.rescans, 1);
  EXPECT_GE(barred.stats.scorings, plain.stats.scorings);  // both scans count
  EXPECT_EQ(barred.stats.windows_nonzero, plain.stats.windows_nonzero);
  ExpectSameBoxes(barred.boxes, plain.boxes);
}

TEST(ProvisionalBarTest, TooFewLocalMaximaLeftIsNotSettled) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 5, 14);
  EdgeBoxParams params = LimitedRefinement(6);
  params.refine_limit = 100000;  // more than any bar leaves: the refined set would change
  const Scan plain = ScanGrid(map, params, 0.f);
  const Scan barred = ScanGrid(map, params, kProvisionalBar);
  EXPECT_EQ(barred.stats.rescans, 1);
  ExpectSameBoxes(barred.boxes, plain.boxes);
}

TEST(ProvisionalBarTest, NotTriedWhereItCannotHelp) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 6, 14);
  // Refining every window (the paper's setting) would refine the removed windows as well.
  EdgeBoxParams paper;
  paper.max_boxes = 6;
  // A grid far smaller than kMinGridWindowsPerBox x max_boxes is unlikely to fill max_boxes.
  const EdgeBoxParams small_grid = LimitedRefinement(1000000);
  for (const EdgeBoxParams& params : {paper, small_grid}) {
    const Scan plain = ScanGrid(map, params, 0.f);
    const Scan barred = ScanGrid(map, params, kProvisionalBar);
    EXPECT_EQ(barred.stats.rescans, 0);
    EXPECT_EQ(barred.stats.scorings, plain.stats.scorings);
    ExpectSameBoxes(barred.boxes, plain.boxes);
  }
}

TEST(ProvisionalBarTest, WithoutRefinementSettledScanIsExact) {
  const cv::Mat1f map = testing::RandomContourMap(140, 100, 7, 14);
  EdgeBoxParams params;
  params.refine = false;
  params.max_boxes = 6;
  const Scan plain = ScanGrid(map, params, 0.f);
  const Scan barred = ScanGrid(map, params, kProvisionalBar);
  EXPECT_EQ(barred.stats.rescans, 0);
  ExpectSameBoxes(barred.boxes, plain.boxes);
  // Nothing above the bar: only NMS not filling up tells that the scan did not settle.
  const Scan unsettled = ScanGrid(map, params, 1000.f);
  EXPECT_EQ(unsettled.stats.rescans, 1);
  ExpectSameBoxes(unsettled.boxes, plain.boxes);
}

}  // namespace
}  // namespace tod
