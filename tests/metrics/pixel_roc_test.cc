#include "core/metrics/pixel_roc.h"

#include <gtest/gtest.h>

#include <random>

namespace tod {
namespace {

// 2 x 3 frame: obstacle pixels P = {0.5, 1.0}, road pixels P = {0.0, 0.25, 0.75}; the pixel
// with P = 0.9 is neither (ignored). All values are exact in float and on the threshold grid.
struct Frame {
  cv::Mat1f p = (cv::Mat1f(2, 3) << 0.0f, 0.5f, 1.0f, 0.25f, 0.75f, 0.9f);
  cv::Mat1b obstacle = (cv::Mat1b(2, 3) << 0, 255, 255, 0, 0, 0);
  cv::Mat1b road = (cv::Mat1b(2, 3) << 255, 0, 0, 255, 255, 0);
};

TEST(PixelRoc, HandComputedCurveWithValuesOnThresholds) {
  const Frame f;
  PixelRocAccumulator roc;
  ASSERT_TRUE(roc.Add(f.p, f.obstacle, f.road).ok());
  EXPECT_EQ(roc.obstacle_pixels(), 2);
  EXPECT_EQ(roc.road_pixels(), 3);
  const RocCurve c = roc.Curve();
  ASSERT_EQ(c.thresholds.size(), 201u);
  EXPECT_EQ(c.thresholds[0], 0.0);
  EXPECT_EQ(c.thresholds[1], 0.005);
  EXPECT_EQ(c.thresholds[100], 0.5);
  EXPECT_EQ(c.thresholds[200], 1.0);
  // t = 0: obstacle {0.5, 1} both > 0; road {0.25, 0.75} > 0, 0.0 is not.
  EXPECT_EQ(c.tpr[0], 1.0);
  EXPECT_DOUBLE_EQ(c.fpr[0], 2.0 / 3.0);
  // t = 0.25 (index 50): road 0.25 is exactly on it, so not > t.
  EXPECT_EQ(c.tpr[50], 1.0);
  EXPECT_DOUBLE_EQ(c.fpr[50], 1.0 / 3.0);
  // t = 0.495 / 0.5: obstacle 0.5 counts below 0.5, not at it.
  EXPECT_EQ(c.tpr[99], 1.0);
  EXPECT_EQ(c.tpr[100], 0.5);
  EXPECT_DOUBLE_EQ(c.fpr[100], 1.0 / 3.0);
  // t = 0.75 (index 150): road 0.75 drops out.
  EXPECT_DOUBLE_EQ(c.fpr[149], 1.0 / 3.0);
  EXPECT_EQ(c.fpr[150], 0.0);
  // t = 0.995: P = 1 still above; t = 1: nothing is.
  EXPECT_EQ(c.tpr[199], 0.5);
  EXPECT_EQ(c.tpr[200], 0.0);
  EXPECT_EQ(c.fpr[200], 0.0);
}

TEST(PixelRoc, CountsArePooledOverFramesNotAveraged) {
  PixelRocAccumulator roc;
  const cv::Mat1b none(1, 4, uchar{0});
  // Frame A: one obstacle pixel at P = 1. Frame B: three obstacle pixels at P = 0.
  ASSERT_TRUE(roc.Add((cv::Mat1f(1, 4) << 1, 0, 0, 0), (cv::Mat1b(1, 4) << 255, 0, 0, 0),
                      (cv::Mat1b(1, 4) << 0, 255, 255, 255))
                  .ok());
  ASSERT_TRUE(roc.Add(cv::Mat1f(1, 4, 0.f), (cv::Mat1b(1, 4) << 0, 255, 255, 255), none).ok());
  const RocCurve c = roc.Curve();
  EXPECT_EQ(roc.obstacle_pixels(), 4);
  EXPECT_EQ(roc.road_pixels(), 3);
  EXPECT_EQ(c.tpr[100], 0.25);  // the mean of per-frame rates would be 0.5
  EXPECT_EQ(c.fpr[100], 0.0);
}

TEST(PixelRoc, HistogramMatchesBruteForceCount) {
  // Random values, half of them exactly on (float-rounded) grid points, against a direct count.
  std::mt19937 gen(3);
  std::uniform_real_distribution<float> uniform(-0.1f, 1.1f);
  std::uniform_int_distribution<int> grid(0, 200);
  std::uniform_int_distribution<int> label(0, 2);
  cv::Mat1f p(17, 23);
  cv::Mat1b obstacle(p.size()), road(p.size());
  for (int y = 0; y < p.rows; ++y) {
    for (int x = 0; x < p.cols; ++x) {
      p(y, x) = (x % 2) ? uniform(gen) : static_cast<float>(grid(gen) / 200.0);
      const int l = label(gen);
      obstacle(y, x) = l == 1 ? 255 : 0;
      road(y, x) = l == 2 ? 255 : 0;
    }
  }
  PixelRocAccumulator roc;
  ASSERT_TRUE(roc.Add(p, obstacle, road).ok());
  const RocCurve c = roc.Curve();
  for (int i = 0; i < 201; ++i) {
    const double t = i / 200.0;
    long long tp = 0, fp = 0, obstacles = 0, roads = 0;
    for (int y = 0; y < p.rows; ++y) {
      for (int x = 0; x < p.cols; ++x) {
        obstacles += obstacle(y, x) != 0;
        roads += road(y, x) != 0;
        if (static_cast<double>(p(y, x)) > t) {
          tp += obstacle(y, x) != 0;
          fp += road(y, x) != 0;
        }
      }
    }
    EXPECT_DOUBLE_EQ(c.tpr[i], static_cast<double>(tp) / obstacles) << "threshold " << i;
    EXPECT_DOUBLE_EQ(c.fpr[i], static_cast<double>(fp) / roads) << "threshold " << i;
  }
}

TEST(PixelRoc, OutOfRangeAndNanProbabilities) {
  PixelRocAccumulator roc(3);  // thresholds 0, 0.5, 1
  ASSERT_TRUE(roc.Add((cv::Mat1f(1, 3) << 1.5f, -0.2f, std::nanf("")), cv::Mat1b(1, 3, uchar{255}),
                      cv::Mat1b(1, 3, uchar{0}))
                  .ok());
  const RocCurve c = roc.Curve();
  ASSERT_EQ(c.thresholds, (std::vector<double>{0.0, 0.5, 1.0}));
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(c.tpr[i], 1.0 / 3.0);  // only 1.5 > every t
  EXPECT_EQ(c.fpr, (std::vector<double>{0.0, 0.0, 0.0}));             // no road pixels
}

TEST(PixelRoc, MismatchedFrameIsAnErrorAndNotCounted) {
  PixelRocAccumulator roc;
  const Status s =
      roc.Add(cv::Mat1f(2, 2, 0.5f), cv::Mat1b(2, 3, uchar{255}), cv::Mat1b(2, 2, uchar{0}));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("obstacle mask is 3x2"), std::string::npos) << s.message();
  EXPECT_FALSE(
      roc.Add(cv::Mat1f(2, 2, 0.5f), cv::Mat1b(2, 2, uchar{255}), cv::Mat1b(1, 1, uchar{0})).ok());
  EXPECT_EQ(roc.obstacle_pixels(), 0);
}

TEST(TprAtFpr, InterpolatesBetweenPointsInFprOrder) {
  // Given in threshold order (FPR descending), as a real curve is.
  const RocCurve curve{{0.0, 0.5, 1.0}, {0.6, 0.4, 0.0}, {0.02, 0.01, 0.0}};
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.005), 0.2);
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.01), 0.4);
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.015), 0.5);
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.0175), 0.55);
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.05), 0.6);  // beyond the curve: end point
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, -1.0), 0.0);
}

TEST(TprAtFpr, DuplicateFprsTakeTheHighestTpr) {
  const RocCurve curve{{0, 0.25, 0.5, 0.75}, {0.7, 0.5, 0.3, 0.1}, {0.02, 0.01, 0.01, 0.0}};
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.01), 0.5);
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.015), 0.6);
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.005), 0.3);  // from (0, 0.1) to (0.01, 0.5)
  EXPECT_DOUBLE_EQ(TprAtFpr(curve, 0.0), 0.1);
  EXPECT_EQ(TprAtFpr(RocCurve{}, 0.01), 0.0);
}

TEST(TprAtFpr, OnAccumulatedCurve) {
  const Frame f;
  PixelRocAccumulator roc;
  ASSERT_TRUE(roc.Add(f.p, f.obstacle, f.road).ok());
  // FPR takes values 2/3, 1/3, 0; at FPR 0 the best TPR is 0.5 (t in [0.75, 1)), at 1/3 it is 1.
  const RocCurve c = roc.Curve();
  EXPECT_DOUBLE_EQ(TprAtFpr(c, 0.0), 0.5);
  EXPECT_DOUBLE_EQ(TprAtFpr(c, 1.0 / 6.0), 0.75);
  EXPECT_DOUBLE_EQ(TprAtFpr(c, 0.9), 1.0);
}

TEST(TprAtFpr, TableOperatingPoints) {
  EXPECT_EQ(TableFprs(), (std::vector<double>{0.005, 0.01, 0.015, 0.02, 0.025, 0.03}));
}

}  // namespace
}  // namespace tod
