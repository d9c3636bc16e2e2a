#include "core/metrics/pixel_histogram_metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <utility>
#include <vector>

namespace tod {
namespace {

// One row of labelled pixels given by their 8-bit levels: a probability of exactly level / 255
// (as float) is served as that level.
struct Row {
  std::vector<int> positive_levels;
  std::vector<int> negative_levels;
  std::vector<int> void_levels;
};

void AddRow(PixelHistogramAccumulator& acc, const Row& row) {
  const int n = static_cast<int>(row.positive_levels.size() + row.negative_levels.size() +
                                 row.void_levels.size());
  cv::Mat1f probability(1, n);
  cv::Mat1b positive(1, n, uchar{0}), negative(1, n, uchar{0});
  int x = 0;
  for (int level : row.positive_levels) {
    probability(0, x) = static_cast<float>(level / 255.0);
    positive(0, x++) = 255;
  }
  for (int level : row.negative_levels) {
    probability(0, x) = static_cast<float>(level / 255.0);
    negative(0, x++) = 255;
  }
  for (int level : row.void_levels) probability(0, x++) = static_cast<float>(level / 255.0);
  const Status added = acc.Add(probability, positive, negative);
  ASSERT_TRUE(added.ok()) << added.message();
}

PixelHistogramAccumulator Accumulate(const Row& row) {
  PixelHistogramAccumulator acc;
  AddRow(acc, row);
  return acc;
}

TEST(PixelHistogramMetrics, PerfectSeparationGivesApOneAndFpr95Zero) {
  const PixelHistogramAccumulator acc = Accumulate({{255, 230, 153}, {128, 51, 0}, {}});
  EXPECT_EQ(acc.positive_pixels(), 3);
  EXPECT_EQ(acc.negative_pixels(), 3);
  EXPECT_DOUBLE_EQ(acc.Ap(), 1.0);
  EXPECT_EQ(acc.FprAtTpr(0.95), 0.0);
}

TEST(PixelHistogramMetrics, FullyInvertedMapGivesThePositiveShareAndFpr95One) {
  // Every negative above every positive: precision first 0, then at full recall only the base
  // rate 2 / (2 + 3); the 95 % TPR is reached only by predicting everything.
  const PixelHistogramAccumulator acc = Accumulate({{0, 0}, {255, 200, 100}, {}});
  EXPECT_DOUBLE_EQ(acc.Ap(), 0.4);
  EXPECT_EQ(acc.FprAtTpr(0.95), 1.0);
}

TEST(PixelHistogramMetrics, HandComputedMixedRanking) {
  // The textbook case: labels (0, 0, 1, 1) at scores (0.1, 0.4, 0.35, 0.8).
  // t = 204: TP 1 FP 0 (P 1, R 0.5); t = 102: TP 1 FP 1 (R unchanged); t = 89: TP 2 FP 1
  // (P 2/3, R 1). AP = 0.5 * 1 + 0.5 * 2/3 = 5/6; TPR >= 0.95 first at t = 89, FPR 1/2.
  const PixelHistogramAccumulator acc = Accumulate({{89, 204}, {25, 102}, {}});
  EXPECT_DOUBLE_EQ(acc.Ap(), 5.0 / 6.0);
  EXPECT_EQ(acc.FprAtTpr(0.95), 0.5);
  const PrecisionRecallCurve pr = acc.PrCurve();
  EXPECT_EQ(pr.levels, (std::vector<int>{204, 102, 89, 25}));
  EXPECT_EQ(pr.recall, (std::vector<double>{0.5, 0.5, 1.0, 1.0}));
  ASSERT_EQ(pr.precision.size(), 4u);
  EXPECT_EQ(pr.precision[0], 1.0);
  EXPECT_EQ(pr.precision[1], 0.5);
  EXPECT_DOUBLE_EQ(pr.precision[2], 2.0 / 3.0);
  EXPECT_EQ(pr.precision[3], 0.5);
}

TEST(PixelHistogramMetrics, BestF1LevelOfTheMixedRanking) {
  // Same ranking: F1 = 2TP / (TP + FP + P) is 2/3 at t = 204, 1/2 at 102, 4/5 at 89, 2/3 at 25.
  EXPECT_EQ(Accumulate({{89, 204}, {25, 102}, {}}).BestF1Level(), 89);
  // Ties go to the higher level: 2/3 at 204 (TP 1) and at 25 (TP 2, FP 2).
  EXPECT_EQ(Accumulate({{25, 204}, {25, 25}, {}}).BestF1Level(), 204);
  EXPECT_EQ(Accumulate({{}, {25, 102}, {}}).BestF1Level(), -1);  // no positive pixel
}

TEST(PixelHistogramMetrics, TiedValuesAreOneThreshold) {
  // A positive and a negative share level 128: one operating point (P 2/3 at R 1), never
  // the positive first (which would give AP 1) nor the negative first.
  // t = 255: P 1 R 0.5; t = 128: TP 2 FP 1. AP = 0.5 + 0.5 * 2/3 = 5/6.
  const PixelHistogramAccumulator acc = Accumulate({{255, 128}, {128, 0}, {}});
  EXPECT_DOUBLE_EQ(acc.Ap(), 5.0 / 6.0);
  EXPECT_EQ(acc.FprAtTpr(0.95), 0.5);
  // All pixels tied: a single threshold at the base rate.
  const PixelHistogramAccumulator flat = Accumulate({{77, 77}, {77, 77, 77, 77, 77, 77}, {}});
  EXPECT_DOUBLE_EQ(flat.Ap(), 0.25);
  EXPECT_EQ(flat.FprAtTpr(0.95), 1.0);
  EXPECT_EQ(flat.PrCurve().levels, std::vector<int>{77});
}

TEST(PixelHistogramMetrics, ValuesWithinOneQuantisationStepTieAsOnTheServedMap) {
  // 0.9995 * 255 = 254.87 and 0.9985 * 255 = 254.62 are both served as 255; values outside
  // [0, 1] clamp. So the positive at 0.9995 and the negative at 0.9985 tie, and so do the
  // positive at 1.3 and the negative at 1.0.
  const cv::Mat1f probability = (cv::Mat1f(1, 6) << 0.9995f, 0.9985f, 1.3f, 1.0f, -0.2f, 0.0f);
  const cv::Mat1b positive = (cv::Mat1b(1, 6) << 255, 0, 255, 0, 255, 0);
  const cv::Mat1b negative = (cv::Mat1b(1, 6) << 0, 255, 0, 255, 0, 255);
  PixelHistogramAccumulator acc;
  ASSERT_TRUE(acc.Add(probability, positive, negative).ok());
  // t = 255: TP 2 FP 2 (P 0.5, R 2/3); t = 0: TP 3 FP 3 (P 0.5, R 1). AP = 0.5.
  EXPECT_DOUBLE_EQ(acc.Ap(), 0.5);
  EXPECT_EQ(acc.PrCurve().levels, (std::vector<int>{255, 0}));
}

TEST(PixelHistogramMetrics, Fpr95TakesTheHighestThresholdReachingTheTargetWithoutInterpolation) {
  Row row;
  // 19 of 20 positives at 200: TPR exactly 0.95 at t = 200, where no negative is predicted.
  row.positive_levels.assign(19, 200);
  row.positive_levels.push_back(10);
  row.negative_levels.assign(10, 100);
  row.negative_levels.resize(20, 5);
  EXPECT_EQ(Accumulate(row).FprAtTpr(0.95), 0.0);
  // 18 of 20 at 200: TPR 0.9 down to t = 11, 1.0 at t = 10 with the 10 negatives at 100 in:
  // FPR 0.5, not a value interpolated between (0.9, 0) and (1.0, 0.5).
  row.positive_levels[18] = 10;
  const PixelHistogramAccumulator acc = Accumulate(row);
  EXPECT_EQ(acc.FprAtTpr(0.95), 0.5);
  EXPECT_EQ(acc.FprAtTpr(0.9), 0.0);
  // The definition over all levels t = 255 .. 0: TPR 0 is met at t = 255, where nothing is
  // predicted; no threshold reaches a TPR above 1.
  EXPECT_EQ(acc.FprAtTpr(0.0), 0.0);
  EXPECT_TRUE(std::isnan(acc.FprAtTpr(1.01)));
}

TEST(PixelHistogramMetrics, VoidPixelsAreNotCountedAndFramesArePooled) {
  PixelHistogramAccumulator pooled;
  AddRow(pooled, {{255}, {0, 0}, {255, 255, 255}});  // frame A
  AddRow(pooled, {{0}, {255}, {128}});               // frame B
  const PixelHistogramAccumulator single = Accumulate({{255, 0}, {0, 0, 255}, {}});
  EXPECT_EQ(pooled.positive_pixels(), 2);
  EXPECT_EQ(pooled.negative_pixels(), 3);
  EXPECT_EQ(pooled.Ap(), single.Ap());
  EXPECT_EQ(pooled.FprAtTpr(0.95), single.FprAtTpr(0.95));
  // t = 255: TP 1 FP 1 (P 0.5, R 0.5); t = 0: TP 2 FP 3 (P 0.4, R 1). AP = 0.25 + 0.2.
  EXPECT_DOUBLE_EQ(pooled.Ap(), 0.45);
}

TEST(PixelHistogramMetrics, NoPositivesLeaveApAndFpr95Undefined) {
  const PixelHistogramAccumulator no_positives = Accumulate({{}, {0, 100, 255}, {50}});
  EXPECT_EQ(no_positives.positive_pixels(), 0);
  EXPECT_TRUE(std::isnan(no_positives.Ap()));
  EXPECT_TRUE(std::isnan(no_positives.FprAtTpr(0.95)));
  EXPECT_TRUE(no_positives.PrCurve().levels.empty());
  const PixelHistogramAccumulator empty;
  EXPECT_TRUE(std::isnan(empty.Ap()));
  EXPECT_TRUE(std::isnan(empty.FprAtTpr(0.95)));
  // Positives without negatives: every prediction is right (AP 1), but no FPR exists.
  const PixelHistogramAccumulator no_negatives = Accumulate({{3, 200}, {}, {}});
  EXPECT_EQ(no_negatives.Ap(), 1.0);
  EXPECT_TRUE(std::isnan(no_negatives.FprAtTpr(0.95)));
}

TEST(PixelHistogramMetrics, MismatchedFrameIsAnErrorAndNotCounted) {
  PixelHistogramAccumulator acc;
  const Status added =
      acc.Add(cv::Mat1f(2, 3, 0.5f), cv::Mat1b(2, 3, uchar{255}), cv::Mat1b(3, 2, uchar{0}));
  EXPECT_FALSE(added.ok());
  EXPECT_NE(added.message().find("3x2"), std::string::npos) << added.message();
  EXPECT_EQ(acc.positive_pixels(), 0);
  EXPECT_EQ(acc.negative_pixels(), 0);
}

// The reference: every labelled pixel sorted by its 8-bit value, descending; an operating point
// closes where the value changes (ties are one threshold).
struct BruteForce {
  double ap = 0;
  double fpr95 = std::nan("");
  std::vector<double> precision, recall;
};

BruteForce SortedPixelMetrics(std::vector<std::pair<int, bool>> pixels) {  // (level, positive)
  std::sort(pixels.begin(), pixels.end(), std::greater<>());
  long long positives = 0, negatives = 0;
  for (const auto& [level, is_positive] : pixels) (is_positive ? positives : negatives) += 1;
  BruteForce out;
  long long tp = 0, fp = 0;
  double previous_recall = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    (pixels[i].second ? tp : fp) += 1;
    if (i + 1 < pixels.size() && pixels[i + 1].first == pixels[i].first) continue;
    const double precision = static_cast<double>(tp) / static_cast<double>(tp + fp);
    const double recall = static_cast<double>(tp) / static_cast<double>(positives);
    out.ap += (recall - previous_recall) * precision;
    previous_recall = recall;
    out.precision.push_back(precision);
    out.recall.push_back(recall);
    if (std::isnan(out.fpr95) && recall >= 0.95)
      out.fpr95 = static_cast<double>(fp) / static_cast<double>(negatives);
  }
  return out;
}

TEST(PixelHistogramMetrics, MatchesBruteForceOnRandomQuantisedMaps) {
  std::mt19937 gen(11);
  std::uniform_int_distribution<int> label(0, 9);  // 0: void, 1-3: obstacle, else free space
  std::uniform_real_distribution<double> jitter(-0.4, 0.4);  // stays off the rounding midpoints
  for (int trial = 0; trial < 5; ++trial) {
    PixelHistogramAccumulator acc;
    std::vector<std::pair<int, bool>> pixels;
    for (int frame = 0; frame < 3; ++frame) {
      cv::Mat1f probability(37, 41);
      cv::Mat1b positive(probability.size(), uchar{0}), negative(probability.size(), uchar{0});
      for (int y = 0; y < probability.rows; ++y) {
        for (int x = 0; x < probability.cols; ++x) {
          const int l = label(gen);
          // Obstacles lean to high values, free space to low ones, with a wide overlap.
          std::normal_distribution<double> level_of(l >= 1 && l <= 3 ? 150.0 : 90.0, 60.0);
          const int level = std::clamp(static_cast<int>(std::lround(level_of(gen))), 0, 255);
          const double value = std::clamp(level + jitter(gen), 0.0, 255.0) / 255.0;
          probability(y, x) = static_cast<float>(value);
          if (l == 0) continue;
          (l <= 3 ? positive : negative)(y, x) = 255;
          pixels.emplace_back(level, l <= 3);
        }
      }
      ASSERT_TRUE(acc.Add(probability, positive, negative).ok());
    }
    const BruteForce expected = SortedPixelMetrics(pixels);
    EXPECT_NEAR(acc.Ap(), expected.ap, 1e-12) << "trial " << trial;
    EXPECT_NEAR(acc.FprAtTpr(0.95), expected.fpr95, 1e-12) << "trial " << trial;
    const PrecisionRecallCurve pr = acc.PrCurve();
    ASSERT_EQ(pr.precision.size(), expected.precision.size());
    for (std::size_t i = 0; i < pr.precision.size(); ++i) {
      EXPECT_NEAR(pr.precision[i], expected.precision[i], 1e-12);
      EXPECT_NEAR(pr.recall[i], expected.recall[i], 1e-12);
    }
    // A map that ranks at all beats the base rate, and the check is not vacuous.
    EXPECT_GT(expected.ap, 0.4);
    EXPECT_GT(expected.fpr95, 0.0);
    EXPECT_LT(expected.fpr95, 1.0);
  }
}

}  // namespace
}  // namespace tod
