#include "core/metrics/component_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

cv::Mat1b Blank() { return cv::Mat1b(40, 60, std::uint8_t{0}); }

void Fill(cv::Mat1b& mask, int x, int y, int w, int h) { mask(cv::Rect(x, y, w, h)) = 255; }

FrameComponents Measure(const cv::Mat1b& predicted, const cv::Mat1b& truth,
                        const cv::Mat1b& void_mask) {
  Result<FrameComponents> m = MeasureComponents(predicted, truth, void_mask);
  EXPECT_TRUE(m.ok()) << m.status().message();
  return m.ok() ? *m : FrameComponents{};
}

// A 10 x 10 obstacle and a 10 x 10 prediction shifted right by 5: |K ∩ P| = 50, |K ∪ P| = 150.
TEST(ComponentMetricsTest, ShiftedPredictionBySIoUAndPpvComputedByHand) {
  cv::Mat1b truth = Blank(), predicted = Blank();
  Fill(truth, 10, 10, 10, 10);
  Fill(predicted, 15, 10, 10, 10);
  const FrameComponents f = Measure(predicted, truth, Blank());
  ASSERT_EQ(f.siou.size(), 1u);
  ASSERT_EQ(f.ppv.size(), 1u);
  EXPECT_DOUBLE_EQ(f.siou[0], 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(f.ppv[0], 0.5);

  ComponentAccumulator acc;
  acc.Add(f);
  const ComponentSummary s = acc.Summary();
  // τ = 0.25, 0.30: TP (sIoU 1/3 >= τ), no FP (PPV 0.5) -> F1 1. τ = 0.35..0.50: FN only -> 0.
  // τ = 0.55..0.75: FN and FP (PPV 0.5 < τ) -> 0. Mean over the 11 τ: 2 / 11.
  ASSERT_EQ(s.f1.size(), 11u);
  EXPECT_DOUBLE_EQ(s.f1[0], 1.0);
  EXPECT_DOUBLE_EQ(s.f1[1], 1.0);
  for (int i = 2; i < 11; ++i) EXPECT_DOUBLE_EQ(s.f1[i], 0.0) << i;
  EXPECT_NEAR(s.mean_f1, 2.0 / 11.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.f1_at_050, 0.0);
  EXPECT_DOUBLE_EQ(s.mean_siou, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.mean_ppv, 0.5);
  EXPECT_EQ(s.truth_components, 1);
  EXPECT_EQ(s.predicted_components, 1);
}

// One prediction covers two obstacles and the gap between them: each obstacle's sIoU does not
// count the other obstacle's pixels against it: 100 / (100 + 300 - 100 - 100) = 0.5.
TEST(ComponentMetricsTest, PredictionOnANeighbourIsNotCountedAgainstAComponent) {
  cv::Mat1b truth = Blank(), predicted = Blank();
  Fill(truth, 0, 0, 10, 10);
  Fill(truth, 20, 0, 10, 10);
  Fill(predicted, 0, 0, 30, 10);
  const FrameComponents f = Measure(predicted, truth, Blank());
  ASSERT_EQ(f.siou.size(), 2u);
  EXPECT_DOUBLE_EQ(f.siou[0], 0.5);
  EXPECT_DOUBLE_EQ(f.siou[1], 0.5);
  ASSERT_EQ(f.ppv.size(), 1u);
  EXPECT_DOUBLE_EQ(f.ppv[0], 200.0 / 300.0);
  // τ = 0.5: 2 TP, no FN, no FP (2/3 >= 0.5) -> F1 1; τ = 0.7: 2 FN and 1 FP -> 0.
  ComponentAccumulator acc;
  acc.Add(f);
  const ComponentSummary s = acc.Summary();
  EXPECT_DOUBLE_EQ(s.f1_at_050, 1.0);
  EXPECT_DOUBLE_EQ(s.f1[9], 0.0);  // τ = 0.70
}

// 8-connectivity: two squares touching at a corner are one component.
TEST(ComponentMetricsTest, DiagonalNeighboursAreOneComponent) {
  cv::Mat1b truth = Blank(), predicted = Blank();
  Fill(truth, 0, 0, 5, 5);
  Fill(truth, 5, 5, 5, 5);
  Fill(predicted, 0, 0, 10, 10);
  const FrameComponents f = Measure(predicted, truth, Blank());
  ASSERT_EQ(f.siou.size(), 1u);
  EXPECT_DOUBLE_EQ(f.siou[0], 50.0 / 100.0);
  EXPECT_DOUBLE_EQ(f.ppv[0], 0.5);
}

// A 3 x 3 obstacle (9 px < 10) is void: no ground-truth component, and the prediction's pixels
// on it are not counted (64 - 9 = 55 px remain, none on an obstacle: PPV 0).
TEST(ComponentMetricsTest, SmallTruthIsVoidAndSmallPredictionsAreDropped) {
  cv::Mat1b truth = Blank(), predicted = Blank();
  Fill(truth, 2, 2, 3, 3);
  Fill(predicted, 0, 0, 8, 8);
  FrameComponents f = Measure(predicted, truth, Blank());
  EXPECT_TRUE(f.siou.empty());
  ASSERT_EQ(f.ppv.size(), 1u);
  EXPECT_DOUBLE_EQ(f.ppv[0], 0.0);

  // A 7 x 7 prediction (49 px < 50) on a 10 x 10 obstacle is dropped: sIoU 0, no PPV.
  truth = Blank();
  predicted = Blank();
  Fill(truth, 20, 20, 10, 10);
  Fill(predicted, 20, 20, 7, 7);
  f = Measure(predicted, truth, Blank());
  ASSERT_EQ(f.siou.size(), 1u);
  EXPECT_DOUBLE_EQ(f.siou[0], 0.0);
  EXPECT_TRUE(f.ppv.empty());
}

// Predicted pixels in void are cleared before the components are formed.
TEST(ComponentMetricsTest, VoidPixelsAreIgnored) {
  cv::Mat1b truth = Blank(), predicted = Blank(), void_mask = Blank();
  Fill(void_mask, 30, 0, 30, 40);
  Fill(predicted, 35, 5, 20, 20);  // wholly in void
  Fill(truth, 0, 0, 10, 10);
  Fill(predicted, 0, 0, 10, 10);  // a perfect hit outside it
  const FrameComponents f = Measure(predicted, truth, void_mask);
  ASSERT_EQ(f.siou.size(), 1u);
  EXPECT_DOUBLE_EQ(f.siou[0], 1.0);
  ASSERT_EQ(f.ppv.size(), 1u);
  EXPECT_DOUBLE_EQ(f.ppv[0], 1.0);
}

// Counts are pooled over frames before F1 is formed (not F1 averaged over frames).
TEST(ComponentMetricsTest, CountsArePooledOverTheSplit) {
  ComponentAccumulator acc;
  acc.Add({{1.0}, {1.0}});       // a hit
  acc.Add({{0.0}, {0.0, 0.0}});  // a miss and two false components
  const ComponentSummary s = acc.Summary();
  // At every τ: TP 1, FN 1, FP 2 -> 2 / (2 + 1 + 2) = 0.4.
  for (double f1 : s.f1) EXPECT_DOUBLE_EQ(f1, 0.4);
  EXPECT_DOUBLE_EQ(s.mean_f1, 0.4);
  EXPECT_DOUBLE_EQ(s.mean_siou, 0.5);
  EXPECT_NEAR(s.mean_ppv, 1.0 / 3.0, 1e-12);
}

TEST(ComponentMetricsTest, EmptySplitIsUndefinedAndMismatchedMasksAreRefused) {
  const ComponentSummary s = ComponentAccumulator().Summary();
  EXPECT_TRUE(std::isnan(s.mean_siou));
  EXPECT_TRUE(std::isnan(s.mean_f1));
  EXPECT_FALSE(MeasureComponents(Blank(), cv::Mat1b(10, 10, std::uint8_t{0}), Blank()).ok());
}

}  // namespace
}  // namespace tod
