#include "core/features/sample_selection.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace tod {
namespace {

// 100x100 frame: rows 50-99 are road; one fully-masked obstacle at (40, 70), 10x10.
// Ranges with limits {99, 59, 19}: V_1 = (59, 99], V_2 = [19, 59].
Sample RoadWithOneObstacle() {
  Sample sample;
  sample.name = "synthetic";
  sample.road = cv::Mat1b(100, 100, uchar{0});
  sample.road.rowRange(50, 100).setTo(255);
  ObstacleInstance obstacle;
  obstacle.id = 1;
  obstacle.box = {40, 70, 10, 10};
  obstacle.mask = cv::Mat1b(10, 10, uchar{255});
  sample.road(obstacle.box.rect()).setTo(0);
  sample.instances.push_back(obstacle);
  return sample;
}

const std::vector<int> kLimits = {99, 59, 19};

TEST(VerticalRangeTest, AssignsBottomRowsToRanges) {
  EXPECT_EQ(VerticalRangeIndex(120, kLimits), 0);  // below y_1 -> V_1
  EXPECT_EQ(VerticalRangeIndex(99, kLimits), 0);
  EXPECT_EQ(VerticalRangeIndex(60, kLimits), 0);
  EXPECT_EQ(VerticalRangeIndex(59, kLimits), 1);
  EXPECT_EQ(VerticalRangeIndex(19, kLimits), 1);  // top range is closed
  EXPECT_EQ(VerticalRangeIndex(3, kLimits), 1);   // above y_{K+1} -> V_K
  const std::vector<int> laf = {840, 712, 653, 514, 374};
  EXPECT_EQ(VerticalRangeIndex(713, laf), 0);
  EXPECT_EQ(VerticalRangeIndex(712, laf), 1);
  EXPECT_EQ(VerticalRangeIndex(653, laf), 2);
  EXPECT_EQ(VerticalRangeIndex(514, laf), 3);
  EXPECT_EQ(VerticalRangeIndex(374, laf), 3);
  EXPECT_EQ(VerticalRangeIndex(100, laf), 3);
  EXPECT_EQ(BottomRow({0, 10, 5, 10}), 19);
}

TEST(CategoryTest, ObstacleRoadBackground) {
  const Sample sample = RoadWithOneObstacle();
  auto table = MaskIoUTable::Build(sample.instances);
  ASSERT_TRUE(table.ok());
  const MaskPixelCounter road(sample.road);
  const SampleSelectionParams params;
  auto category = [&](const Box& b) {
    return CategorizeProposal(b, *table, road, MaskPixelCounter(), params);
  };
  EXPECT_EQ(category({40, 70, 10, 10}), ProposalCategory::kObstacle);
  EXPECT_EQ(category({40, 70, 10, 5}), ProposalCategory::kObstacle);  // IoU 50/100 = 0.5
  // IoU 0.4 and no road: obstacle pixels are not road pixels.
  EXPECT_EQ(category({40, 70, 10, 4}), ProposalCategory::kBackground);
  EXPECT_EQ(category({0, 60, 10, 10}), ProposalCategory::kRoad);
  EXPECT_EQ(category({0, 10, 10, 10}), ProposalCategory::kBackground);
  EXPECT_EQ(category({0, 45, 10, 10}), ProposalCategory::kBackground);  // exactly 50 % road
  EXPECT_EQ(category({0, 46, 10, 10}), ProposalCategory::kRoad);        // 60 % road
  // Whole obstacle inside a 20x10 box: IoU 100 / 200 = 0.5 -> obstacle.
  EXPECT_EQ(category({35, 70, 20, 10}), ProposalCategory::kObstacle);
  // 30x10 box around it: IoU 100 / 300, road 200 of 300 -> road.
  EXPECT_EQ(category({30, 70, 30, 10}), ProposalCategory::kRoad);
}

// Void is neither road nor background: the road share is taken over a box's scored pixels.
TEST(CategoryTest, VoidPixelsAreNotCounted) {
  const Sample sample = RoadWithOneObstacle();
  auto table = MaskIoUTable::Build(sample.instances);
  ASSERT_TRUE(table.ok());
  const MaskPixelCounter road(sample.road);
  cv::Mat1b void_mask(100, 100, uchar{0});
  void_mask(cv::Rect(0, 0, 100, 50)).setTo(255);  // the upper half, beside the road, is void
  const MaskPixelCounter void_pixels(void_mask);
  const SampleSelectionParams params;
  auto category = [&](const Box& b, const MaskPixelCounter& v) {
    return CategorizeProposal(b, *table, road, v, params);
  };
  // 30 % road, 70 % void: every scored pixel is road.
  EXPECT_EQ(category({0, 43, 10, 10}, MaskPixelCounter()), ProposalCategory::kBackground);
  EXPECT_EQ(category({0, 43, 10, 10}, void_pixels), ProposalCategory::kRoad);
  // All void: nothing scored, background (never drawn as a road negative).
  EXPECT_EQ(category({0, 10, 10, 10}, void_pixels), ProposalCategory::kBackground);
  // The obstacle test does not change: IoU decides first.
  EXPECT_EQ(category({40, 70, 10, 10}, void_pixels), ProposalCategory::kObstacle);
}

struct Scene {
  std::vector<ScoredBox> proposals;
  std::vector<int> exact, shift1, shift2_tie_a, shift2_tie_b, low_iou;  // single indices
};

// Proposals with known categories and ranges:
//  V_1 road: 30 boxes (10 hard, 20 easy) + one low-IoU obstacle overlap (hard, road category)
//  V_1 background: 5 boxes straddling the road border at exactly 50 % road
//  V_2 road: 3 easy boxes; V_2 background: 40 boxes (15 hard, 25 easy)
//  positives: IoU 1, 90/110, two at 80/120, one at 25/175.
Scene MakeScene() {
  Scene s;
  auto add = [&](Box b, float score) {
    s.proposals.push_back({b, score});
    return static_cast<int>(s.proposals.size()) - 1;
  };
  for (int i = 0; i < 30; ++i) add({(i % 6) * 5, 60 + (i / 6), 10, 10}, i < 10 ? 0.6f : 0.1f);
  for (int i = 0; i < 5; ++i) add({60 + i, 35, 10, 30}, 0.1f);      // bottom 64 -> V_1
  for (int i = 0; i < 3; ++i) add({60 + 5 * i, 50, 10, 10}, 0.1f);  // bottom 59 -> V_2
  for (int i = 0; i < 40; ++i) add({i, 5 + (i % 10), 10, 10}, i < 15 ? 0.5f : 0.2f);
  s.exact = {add({40, 70, 10, 10}, 0.9f)};
  s.shift1 = {add({41, 70, 10, 10}, 0.9f)};
  s.shift2_tie_a = {add({42, 70, 10, 10}, 0.9f)};
  s.shift2_tie_b = {add({40, 72, 10, 10}, 0.9f)};
  s.low_iou = {add({45, 75, 10, 10}, 0.9f)};
  return s;
}

SampleSelectionParams SmallParams() {
  SampleSelectionParams params;
  params.ordr_negatives = {17, 17};
  params.obdr_negatives = {25, 25};
  params.positives = {3, 3};
  return params;
}

int CountIf(const std::vector<int>& indices, const std::vector<ScoredBox>& proposals, int range,
            bool hard) {
  return static_cast<int>(std::count_if(indices.begin(), indices.end(), [&](int i) {
    return VerticalRangeIndex(BottomRow(proposals[i].box), kLimits) == range &&
           (proposals[i].score > 0.3f) == hard;
  }));
}

TEST(SampleSelectionTest, PositivesAreTopIoUBoxes) {
  const Scene scene = MakeScene();
  auto selected =
      SelectTrainingSamples(scene.proposals, RoadWithOneObstacle(), kLimits, SmallParams(), 7);
  ASSERT_TRUE(selected.ok()) << selected.status().message();
  // Top 3 by IoU: 1.0, 90/110, then the 80/120 tie resolved by the lower index.
  const std::vector<int> expected = {scene.exact[0], scene.shift1[0], scene.shift2_tie_a[0]};
  EXPECT_EQ(selected->positive_indices, expected);
  ASSERT_GE(selected->ordr_indices.size(), 3u);
  ASSERT_GE(selected->obdr_indices.size(), 3u);
  for (int j = 0; j < 3; ++j) {
    EXPECT_EQ(selected->ordr_indices[j], expected[j]);
    EXPECT_EQ(selected->obdr_indices[j], expected[j]);
  }
  EXPECT_FLOAT_EQ(selected->ordr_targets[0], 1.f);
  EXPECT_FLOAT_EQ(selected->ordr_targets[1], static_cast<float>(90.0 / 110.0));
  EXPECT_FLOAT_EQ(selected->ordr_targets[2], static_cast<float>(80.0 / 120.0));
}

TEST(SampleSelectionTest, NegativeCountsPerRangeAndHardEasySplit) {
  const Scene scene = MakeScene();
  const Sample gt = RoadWithOneObstacle();
  auto selected = SelectTrainingSamples(scene.proposals, gt, kLimits, SmallParams(), 11);
  ASSERT_TRUE(selected.ok());
  const std::vector<int> ordr(selected->ordr_indices.begin() + 3, selected->ordr_indices.end());
  const std::vector<int> obdr(selected->obdr_indices.begin() + 3, selected->obdr_indices.end());
  // ORDR V_1: 17 of 31 road candidates, round(0.2 * 17) = 3 hard. V_2: only 3 road boxes.
  EXPECT_EQ(CountIf(ordr, scene.proposals, 0, true), 3);
  EXPECT_EQ(CountIf(ordr, scene.proposals, 0, false), 14);
  EXPECT_EQ(CountIf(ordr, scene.proposals, 1, false) + CountIf(ordr, scene.proposals, 1, true), 3);
  EXPECT_EQ(ordr.size(), 20u);
  // OBDR V_1: all 5 background boxes; V_2: 25 of 40, round(0.2 * 25) = 5 hard.
  EXPECT_EQ(CountIf(obdr, scene.proposals, 0, false), 5);
  EXPECT_EQ(CountIf(obdr, scene.proposals, 0, true), 0);
  EXPECT_EQ(CountIf(obdr, scene.proposals, 1, true), 5);
  EXPECT_EQ(CountIf(obdr, scene.proposals, 1, false), 20);
  EXPECT_EQ(obdr.size(), 30u);

  // Every negative has the right category, IoU < 0.5, no duplicates, and is not a positive.
  auto table = MaskIoUTable::Build(gt.instances);
  const MaskPixelCounter road(gt.road);
  const SampleSelectionParams params = SmallParams();
  const std::set<int> positives(selected->positive_indices.begin(),
                                selected->positive_indices.end());
  for (const int i : ordr) {
    EXPECT_EQ(CategorizeProposal(scene.proposals[i].box, *table, road, MaskPixelCounter(), params),
              ProposalCategory::kRoad);
    EXPECT_FALSE(positives.count(i));
  }
  for (const int i : obdr) {
    EXPECT_EQ(CategorizeProposal(scene.proposals[i].box, *table, road, MaskPixelCounter(), params),
              ProposalCategory::kBackground);
  }
  EXPECT_EQ(std::set<int>(ordr.begin(), ordr.end()).size(), ordr.size());
  EXPECT_EQ(std::set<int>(obdr.begin(), obdr.end()).size(), obdr.size());
  // Targets are the max mask IoU: 0 for every box not touching the obstacle.
  for (std::size_t j = 3; j < selected->ordr_indices.size(); ++j) {
    const int i = selected->ordr_indices[j];
    EXPECT_FLOAT_EQ(selected->ordr_targets[j],
                    static_cast<float>(table->MaxIoU(scene.proposals[i].box)));
  }
}

TEST(SampleSelectionTest, TopsUpFromTheOtherPoolWhenShort) {
  Sample gt = RoadWithOneObstacle();
  gt.instances.clear();
  std::vector<ScoredBox> proposals;
  // V_1 road: 1 hard, 30 easy. V_2 road: 30 hard, 2 easy.
  proposals.push_back({{0, 60, 10, 10}, 0.9f});
  for (int i = 0; i < 30; ++i) proposals.push_back({{i, 61, 10, 10}, 0.1f});
  for (int i = 0; i < 30; ++i) proposals.push_back({{i, 50, 10, 10}, 0.9f});
  for (int i = 0; i < 2; ++i) proposals.push_back({{i, 49, 10, 11}, 0.1f});
  SampleSelectionParams params = SmallParams();
  params.ordr_negatives = {10, 10};
  params.hard_fraction = 0.5;
  auto selected = SelectTrainingSamples(proposals, gt, kLimits, params, 3);
  ASSERT_TRUE(selected.ok());
  EXPECT_TRUE(selected->positive_indices.empty());
  const std::vector<int>& ordr = selected->ordr_indices;
  EXPECT_EQ(CountIf(ordr, proposals, 0, true), 1);   // the only hard one
  EXPECT_EQ(CountIf(ordr, proposals, 0, false), 9);  // 5 easy + 4 topping up
  EXPECT_EQ(CountIf(ordr, proposals, 1, false), 2);  // both easy ones
  EXPECT_EQ(CountIf(ordr, proposals, 1, true), 8);   // 5 hard + 3 topping up
  EXPECT_TRUE(selected->obdr_indices.empty());       // no background proposals at all
}

TEST(SampleSelectionTest, DeterministicForSeed) {
  const Scene scene = MakeScene();
  const Sample gt = RoadWithOneObstacle();
  auto a = SelectTrainingSamples(scene.proposals, gt, kLimits, SmallParams(), 5);
  auto b = SelectTrainingSamples(scene.proposals, gt, kLimits, SmallParams(), 5);
  auto c = SelectTrainingSamples(scene.proposals, gt, kLimits, SmallParams(), 6);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(a->ordr_indices, b->ordr_indices);
  EXPECT_EQ(a->obdr_indices, b->obdr_indices);
  // A different seed draws a different subset (17 of 31 and 25 of 40: a repeat is ~1e-8).
  EXPECT_NE(a->ordr_indices, c->ordr_indices);
}

TEST(SampleSelectionTest, BoxIoUTargetFlag) {
  Sample gt = RoadWithOneObstacle();
  gt.instances[0].mask.rowRange(5, 10).setTo(0);  // only the top half is obstacle
  const std::vector<ScoredBox> proposals = {{{40, 70, 10, 10}, 0.9f}};
  SampleSelectionParams params = SmallParams();
  auto mask_target = SelectTrainingSamples(proposals, gt, kLimits, params, 1);
  params.box_iou_target = true;
  auto box_target = SelectTrainingSamples(proposals, gt, kLimits, params, 1);
  ASSERT_TRUE(mask_target.ok() && box_target.ok());
  ASSERT_EQ(mask_target->ordr_targets.size(), 1u);
  EXPECT_FLOAT_EQ(mask_target->ordr_targets[0], 0.5f);  // 50 / (50 + 100 - 50)
  EXPECT_FLOAT_EQ(box_target->ordr_targets[0], 1.f);
}

TEST(SampleSelectionTest, BadInputIsAnError) {
  const Sample gt = RoadWithOneObstacle();
  const std::vector<ScoredBox> none;
  auto not_decreasing = SelectTrainingSamples(none, gt, {19, 59, 99}, SmallParams(), 1);
  ASSERT_FALSE(not_decreasing.ok());
  EXPECT_NE(not_decreasing.status().message().find("range_limits"), std::string::npos);
  auto wrong_k = SelectTrainingSamples(none, gt, {99, 59, 39, 19}, SmallParams(), 1);
  ASSERT_FALSE(wrong_k.ok());
  EXPECT_NE(wrong_k.status().message().find("ordr_negatives"), std::string::npos);
  Sample no_road = gt;
  no_road.road.release();
  EXPECT_FALSE(SelectTrainingSamples(none, no_road, kLimits, SmallParams(), 1).ok());
  Sample bad_mask = gt;
  bad_mask.instances[0].mask = cv::Mat1b(3, 3, uchar{255});
  auto bad = SelectTrainingSamples(none, bad_mask, kLimits, SmallParams(), 1);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("synthetic"), std::string::npos);
  EXPECT_NE(bad.status().message().find("instance 1"), std::string::npos);
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

// Without a road label (obstacle-mask benchmarks) `road` is every non-obstacle pixel: both
// regressors draw their negatives from the same non-obstacle pool, independently.
// RoadWithOneObstacle as an obstacle-mask benchmark has it: every non-obstacle pixel is free.
Sample WithoutRoadLabel() {
  Sample gt = RoadWithOneObstacle();
  gt.free_space = FreeSpace::kNotObstacle;
  gt.road.setTo(255);
  gt.road(gt.instances[0].box.rect()).setTo(0);
  return gt;
}

// 10 x 10 boxes over the 100 x 100 frame every `step_x`, `step_y` pixels.
std::vector<ScoredBox> GridOfBoxes(int step_x, int step_y) {
  std::vector<ScoredBox> proposals;
  for (int y = 0; y + 10 <= 100; y += step_y)
    for (int x = 0; x + 10 <= 100; x += step_x) proposals.push_back({{x, y, 10, 10}, 0.1f});
  return proposals;
}

TEST(SampleSelectionTest, WithoutRoadLabelBothRegressorsDrawFromEveryNonObstacleBox) {
  const Sample gt = WithoutRoadLabel();
  const std::vector<ScoredBox> proposals = GridOfBoxes(10, 10);
  auto selected = SelectTrainingSamples(proposals, gt, kLimits, SmallParams(), 3);
  ASSERT_TRUE(selected.ok()) << selected.status().message();
  const std::size_t positives = selected->positive_indices.size();
  EXPECT_GT(selected->obdr_indices.size(), positives + 20);  // negatives despite no background
  EXPECT_GT(selected->ordr_indices.size(), positives + 20);
  EXPECT_NE(selected->ordr_indices, selected->obdr_indices);  // independent draws
}

}  // namespace
}  // namespace tod
