#include "core/pipeline/obstacle_calibration.h"

#include <gtest/gtest.h>

#include <random>

#include "core/pipeline/pipeline_params.h"

namespace tod {
namespace {

TEST(ObstacleCalibrationTest, PlattFitRecoversALogisticRelation) {
  // Labels drawn from p(e) = sigmoid(8 e - 4): the fit must come back close to (8, -4).
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> evidence;
  std::vector<int> labels;
  for (int i = 0; i < 20000; ++i) {
    const double e = u(rng);
    evidence.push_back(e);
    labels.push_back(u(rng) < 1.0 / (1.0 + std::exp(-(8 * e - 4))) ? 1 : 0);
  }
  auto fit = FitObstacleCalibration(evidence, labels);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_TRUE(fit->fitted);
  EXPECT_NEAR(fit->slope, 8.0, 0.5);
  EXPECT_NEAR(fit->intercept, -4.0, 0.3);
  EXPECT_NEAR(CalibratedScore(*fit, 0.5), 0.5, 0.03);
  EXPECT_LT(CalibratedScore(*fit, 0.2), CalibratedScore(*fit, 0.8));
}

TEST(ObstacleCalibrationTest, SeparableDataStaysFinite) {
  auto fit = FitObstacleCalibration({0.1, 0.2, 0.3, 0.7, 0.8, 0.9}, {0, 0, 0, 1, 1, 1});
  ASSERT_TRUE(fit.ok());
  EXPECT_TRUE(std::isfinite(fit->slope));
  EXPECT_GT(CalibratedScore(*fit, 0.9), 0.5);
  EXPECT_LT(CalibratedScore(*fit, 0.1), 0.5);
}

TEST(ObstacleCalibrationTest, EvidenceThatRanksObstaclesLastGivesAFlatNotAnInvertedScore) {
  // Obstacles at low evidence, the rest at high: unconstrained, Platt's slope is negative and a
  // stronger box would score lower. Held monotone, every evidence scores the smoothed base rate.
  const std::vector<double> evidence = {0.1, 0.15, 0.2, 0.6, 0.7, 0.8, 0.9, 0.95};
  const std::vector<int> labels = {1, 1, 0, 0, 0, 0, 0, 0};
  auto fit = FitObstacleCalibration(evidence, labels);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_TRUE(fit->fitted);
  EXPECT_TRUE(fit->flat);
  EXPECT_EQ(fit->slope, 0.0);
  const double hi = 3.0 / 4.0, lo = 1.0 / 8.0;  // Platt's targets for 2 positives, 6 negatives
  const double base_rate = (2 * hi + 6 * lo) / 8.0;
  EXPECT_NEAR(CalibratedScore(*fit, 0.1), base_rate, 1e-9);
  EXPECT_NEAR(CalibratedScore(*fit, 0.95), base_rate, 1e-9);
  // Evidence that does rank obstacles first is not flattened.
  auto ranked = FitObstacleCalibration(evidence, {0, 0, 0, 0, 0, 0, 1, 1});
  ASSERT_TRUE(ranked.ok());
  EXPECT_FALSE(ranked->flat);
  EXPECT_GT(ranked->slope, 0.0);
}

TEST(ObstacleCalibrationTest, ParametersWithANegativeSlopeAreRefused) {
  PipelineParams params;
  params.obstacle_calibration = {.fitted = true, .slope = -3.7, .intercept = 0.8};
  const auto parsed = PipelineParamsFromJson(ToJson(params));
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.status().message().find("obstacle_calibration.slope"), std::string::npos)
      << parsed.status().message();
  params.obstacle_calibration = {.fitted = true, .slope = 0.0, .intercept = -1.2, .flat = true};
  const auto flat = PipelineParamsFromJson(ToJson(params));
  ASSERT_TRUE(flat.ok()) << flat.status().message();
  EXPECT_TRUE(flat->obstacle_calibration.flat);
  EXPECT_DOUBLE_EQ(flat->obstacle_calibration.intercept, -1.2);
}

TEST(ObstacleCalibrationTest, NeedsBothClassesAndUnfittedPassesEvidenceThrough) {
  EXPECT_FALSE(FitObstacleCalibration({0.1, 0.2}, {1, 1}).ok());
  EXPECT_FALSE(FitObstacleCalibration({0.1, 0.2}, {0, 0}).ok());
  EXPECT_FALSE(FitObstacleCalibration({0.1}, {0, 1}).ok());
  EXPECT_DOUBLE_EQ(CalibratedScore(ObstacleCalibration{}, 0.37), 0.37);
}

TEST(PriorCorrectionTest, UndoesBalancedSamplingOdds) {
  cv::Mat1f p = (cv::Mat1f(1, 5) << 0.f, 0.5f, 0.9f, 1.f, 0.2f);
  CorrectSampledPrior(p, 0.01);
  EXPECT_EQ(p(0, 0), 0.f);
  EXPECT_NEAR(p(0, 1), 0.01 / 1.01, 1e-6);  // odds 1 -> 0.01
  EXPECT_NEAR(p(0, 2), 0.09 / 1.09, 1e-6);  // odds 9 -> 0.09
  EXPECT_EQ(p(0, 3), 1.f);
  cv::Mat1f unchanged = (cv::Mat1f(1, 2) << 0.3f, 0.7f);
  CorrectSampledPrior(unchanged, 1.0);
  EXPECT_EQ(unchanged(0, 0), 0.3f);
  EXPECT_EQ(unchanged(0, 1), 0.7f);
}

}  // namespace
}  // namespace tod
