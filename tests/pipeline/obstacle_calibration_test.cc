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
