#include "core/metrics/instance_recall.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

// GT 10 x 10 at the origin; proposals ranked with IoU 0, 0.5, 0.8, 1 to it.
const Box kGt{0, 0, 10, 10};
const std::vector<Box> kRanked = {{20, 20, 5, 5}, {0, 0, 10, 5}, {0, 0, 10, 8}, {0, 0, 10, 10}};

TEST(Recall, StrictThresholdAndRankCutoff) {
  RecallAccumulator acc;
  acc.Add(kRanked, {kGt});
  ASSERT_EQ(acc.instances(), 1);
  EXPECT_EQ(acc.BestIoU(0, 1), 0.0);
  EXPECT_EQ(acc.BestIoU(0, 2), 0.5);
  EXPECT_EQ(acc.BestIoU(0, 3), 0.8);
  EXPECT_EQ(acc.BestIoU(0, 1000), 1.0);
  EXPECT_EQ(acc.Recall(0, 0.0), 0.0);  // N = 0: no proposals, a miss
  EXPECT_EQ(acc.Recall(1, 0.0), 0.0);  // IoU 0 is not > 0
  EXPECT_EQ(acc.Recall(2, 0.5), 0.0);  // IoU exactly 0.5 is not > 0.5
  EXPECT_EQ(acc.Recall(2, 0.45), 1.0);
  EXPECT_EQ(acc.Recall(3, 0.7), 1.0);
  EXPECT_EQ(acc.Recall(3, 0.8), 0.0);  // 64 / 80 == 0.8 exactly
  EXPECT_EQ(acc.Recall(4, 0.95), 1.0);
  EXPECT_EQ(acc.Recall(1000, 1.0), 0.0);  // tau = 1 never counts
}

TEST(Recall, AverageRecallOverElevenThresholds) {
  ASSERT_EQ(RecallIouThresholds().size(), 11u);
  EXPECT_EQ(RecallIouThresholds().front(), 0.5);
  EXPECT_EQ(RecallIouThresholds()[4], 0.7);
  EXPECT_EQ(RecallIouThresholds().back(), 1.0);
  RecallAccumulator acc;
  acc.Add(kRanked, {kGt});
  EXPECT_EQ(acc.AverageRecall(2), 0.0);                 // best IoU 0.5
  EXPECT_DOUBLE_EQ(acc.AverageRecall(3), 6.0 / 11.0);   // 0.8 > 0.50 ... 0.75
  EXPECT_DOUBLE_EQ(acc.AverageRecall(4), 10.0 / 11.0);  // 1.0 > all but 1.00
}

TEST(Recall, NoProposalsAreMissesAndFramesWithoutObstaclesAddNothing) {
  RecallAccumulator acc;
  acc.Add({}, {kGt});       // a miss
  acc.Add(kRanked, {});     // adds nothing
  acc.Add(kRanked, {kGt});  // a hit at IoU 1 with N >= 4
  EXPECT_EQ(acc.instances(), 2);
  EXPECT_EQ(acc.Recall(4, 0.7), 0.5);
  EXPECT_EQ(RecallAccumulator().Recall(1000, 0.5), 0.0);  // no instances at all
  EXPECT_EQ(RecallAccumulator().AverageRecall(1000), 0.0);
}

TEST(Recall, TiesAndSharedProposals) {
  // Two equal best proposals at ranks 1 and 2: the first one decides; one proposal may cover
  // two instances.
  RecallAccumulator acc;
  const std::vector<Box> ranked = {{50, 50, 4, 4}, {0, 0, 10, 10}, {0, 0, 10, 10}};
  acc.Add(ranked, {kGt, Box{0, 0, 10, 10}, Box{50, 50, 4, 4}});
  EXPECT_EQ(acc.Recall(1, 0.9), 1.0 / 3.0);
  EXPECT_EQ(acc.Recall(2, 0.9), 1.0);
  EXPECT_EQ(acc.BestIoU(0, 3), 1.0);
}

TEST(Recall, OnlyTheFirstMaxProposalsCount) {
  RecallAccumulator acc(2);
  acc.Add(kRanked, {kGt});
  EXPECT_EQ(acc.max_proposals(), 2);
  EXPECT_EQ(acc.BestIoU(0, 1000), 0.5);  // ranks 2, 3 never looked at; n clamped to 2
  EXPECT_EQ(acc.Recall(1000, 0.45), 1.0);
}

TEST(Recall, BoxesAtTheImageBorderAreClipped) {
  // Image 20 x 10. GT touches the right border; the proposal sticks out by 5 columns.
  const Box gt{15, 0, 5, 10};
  const std::vector<Box> ranked = {{15, 0, 10, 10}};
  RecallAccumulator unclipped, clipped;
  unclipped.Add(ranked, {gt});
  EXPECT_EQ(unclipped.BestIoU(0, 1), 0.5);  // 50 of 100 pixels, half outside the image
  ASSERT_TRUE(clipped.Add(ranked, {gt}, 20, 10).ok());
  EXPECT_EQ(clipped.BestIoU(0, 1), 1.0);
  // Top-left corner: proposal from (-5, -5), 10 x 10, keeps 5 x 5 pixels inside.
  RecallAccumulator corner;
  ASSERT_TRUE(corner.Add({Box{-5, -5, 10, 10}}, {Box{0, 0, 5, 10}}, 20, 10).ok());
  EXPECT_EQ(corner.BestIoU(0, 1), 0.5);  // 25 / (25 + 50 - 25)
  const Status bad = corner.Add(ranked, {gt}, 0, 10);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("image size 0x10"), std::string::npos);
  EXPECT_EQ(corner.instances(), 1);
}

}  // namespace
}  // namespace tod
