#include "core/proposals/edge_orientation.h"

#include <gtest/gtest.h>

#include <numbers>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

TEST(EdgeOrientationTest, DerivativesAreCentralInsideAndOneSidedAtBorders) {
  cv::Mat1f m = (cv::Mat1f(2, 4) << 0, 1, 4, 9, 1, 1, 1, 1);
  const cv::Mat1f dx = DerivativeX(m);
  EXPECT_FLOAT_EQ(dx(0, 0), 1.f);  // 1 - 0
  EXPECT_FLOAT_EQ(dx(0, 1), 2.f);  // (4 - 0) / 2
  EXPECT_FLOAT_EQ(dx(0, 2), 4.f);  // (9 - 1) / 2
  EXPECT_FLOAT_EQ(dx(0, 3), 5.f);  // 9 - 4
  EXPECT_FLOAT_EQ(dx(1, 2), 0.f);
  const cv::Mat1f dy = DerivativeY(m);
  EXPECT_FLOAT_EQ(dy(0, 0), 1.f);  // one-sided: 1 - 0
  EXPECT_FLOAT_EQ(dy(1, 3), -8.f);
  EXPECT_FLOAT_EQ(DerivativeX(cv::Mat1f(3, 1, 5.f))(1, 0), 0.f);  // single column
}

TEST(EdgeOrientationTest, DiagonalRidgesGetTheirNormalAngles) {
  // Ridge along y = x: f = g(x - y), Oxx = Oyy = g'' < 0 and Oxy = -g'' > 0 on the ridge, so
  // theta = mod(atan(g'' * sign(g'') / g''), pi) = mod(-pi / 4, pi) = 3 pi / 4.
  cv::Mat1f diagonal(41, 41, 0.f), anti(41, 41, 0.f);
  for (int i = 0; i < 41; ++i) {
    diagonal(i, i) = 1.f;
    anti(i, 40 - i) = 1.f;
  }
  EXPECT_NEAR(ComputeEdgeOrientation(diagonal)(20, 20), 3.f * kPi / 4.f, 1e-3f);
  // Ridge along y = -x: Oxy = g'' < 0, theta = atan(1) = pi / 4.
  EXPECT_NEAR(ComputeEdgeOrientation(anti)(20, 20), kPi / 4.f, 1e-3f);
}

TEST(EdgeOrientationTest, RangeAndDegenerateSizes) {
  cv::Mat1f m(30, 30, 0.f);
  cv::circle(m, {15, 15}, 9, cv::Scalar(1.f));
  const cv::Mat1f theta = ComputeEdgeOrientation(m);
  double lo = 0, hi = 0;
  cv::minMaxLoc(theta, &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_LT(hi, kPi);
  EXPECT_TRUE(ComputeEdgeOrientation(cv::Mat1f()).empty());
  EXPECT_EQ(ComputeEdgeOrientation(cv::Mat1f(1, 1, 1.f)).size(), cv::Size(1, 1));
  EXPECT_EQ(ComputeEdgeOrientation(cv::Mat1f(3, 200, 0.5f)).size(), cv::Size(200, 3));
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

TEST(EdgeOrientationTest, MaskedVariantEqualsFullOnEdgePixelsAndIsZeroElsewhere) {
  cv::Mat1f map(30, 40, 0.f);
  cv::circle(map, {20, 15}, 9, cv::Scalar(0.8f));
  cv::line(map, {0, 3}, {39, 25}, cv::Scalar(0.05f));  // below the threshold
  const cv::Mat1f full = ComputeEdgeOrientation(map);
  const cv::Mat1f masked = ComputeEdgeOrientation(map, 0.1f);
  int edges = 0;
  for (int r = 0; r < map.rows; ++r) {
    for (int c = 0; c < map.cols; ++c) {
      if (map(r, c) > 0.1f) {
        EXPECT_EQ(masked(r, c), full(r, c));
        ++edges;
      } else {
        EXPECT_EQ(masked(r, c), 0.f);
      }
    }
  }
  EXPECT_GT(edges, 40);
}

}  // namespace
}  // namespace tod
