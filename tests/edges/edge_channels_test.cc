#include "core/edges/edge_channels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

TEST(TriangleSmooth, RadiusOneImpulseGivesOuterProductOfOneTwoOne) {
  cv::Mat1f impulse = cv::Mat1f::zeros(7, 7);
  impulse(3, 3) = 16.f;
  const cv::Mat1f smoothed = TriangleSmooth(impulse, 1);
  EXPECT_FLOAT_EQ(smoothed(3, 3), 4.f);  // 16 * (2/4) * (2/4)
  EXPECT_FLOAT_EQ(smoothed(3, 4), 2.f);  // 16 * (2/4) * (1/4)
  EXPECT_FLOAT_EQ(smoothed(2, 2), 1.f);  // 16 * (1/4) * (1/4)
  EXPECT_FLOAT_EQ(smoothed(3, 5), 0.f);
  EXPECT_NEAR(cv::sum(smoothed)[0], 16.0, 1e-4);
}

TEST(TriangleSmooth, RadiusTwoWeightsAreOneTwoThreeTwoOneOverNine) {
  cv::Mat1f impulse = cv::Mat1f::zeros(1, 9);
  impulse(0, 4) = 81.f;
  const cv::Mat1f smoothed = TriangleSmooth(impulse, 2);
  // Vertical pass on a single row with reflected border: 1+2+3+2+1 weights over the same row.
  EXPECT_FLOAT_EQ(smoothed(0, 4), 81.f * 3.f / 9.f);
  EXPECT_FLOAT_EQ(smoothed(0, 3), 81.f * 2.f / 9.f);
  EXPECT_FLOAT_EQ(smoothed(0, 2), 81.f * 1.f / 9.f);
  EXPECT_FLOAT_EQ(smoothed(0, 1), 0.f);
}

TEST(TriangleSmooth, RadiusZeroIsACopy) {
  cv::Mat1f values(2, 2);
  values << 1.f, 2.f, 3.f, 4.f;
  const cv::Mat1f copy = TriangleSmooth(values, 0);
  EXPECT_EQ(cv::norm(copy, values, cv::NORM_INF), 0.0);
  EXPECT_NE(copy.data, values.data);
}

TEST(BgrToLuv, WhiteIsLightnessOneWithoutChroma) {
  const cv::Mat3f luv = BgrToLuv(cv::Mat3b(1, 2, cv::Vec3b(255, 255, 255)));
  EXPECT_NEAR(luv(0, 0)[0], 1.f, 1e-3);
  EXPECT_NEAR(luv(0, 0)[1], 0.f, 1e-2);
  EXPECT_NEAR(luv(0, 0)[2], 0.f, 1e-2);
  const cv::Mat3f black = BgrToLuv(cv::Mat3b(1, 1, cv::Vec3b(0, 0, 0)));
  EXPECT_NEAR(black(0, 0)[0], 0.f, 1e-4);
}

TEST(ColourGradient, RampGivesSlopeAndOrientationOfTheSteepestChannel) {
  cv::Mat3f luv(5, 6);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 6; ++x) luv(y, x) = cv::Vec3f(0.1f * x, 0.3f * y, 0.f);
  }
  const ColourGradient gradient = ComputeColourGradient(luv, true);
  // Channel 1 (vertical slope 0.3) beats channel 0 (horizontal slope 0.1) at interior pixels.
  EXPECT_NEAR(gradient.magnitude(2, 2), 0.3f, 1e-6);
  EXPECT_NEAR(gradient.orientation(2, 2), kPi / 2, 1e-6);
  // Top border: replicated row halves the vertical difference to 0.15, still the largest.
  EXPECT_NEAR(gradient.magnitude(0, 2), 0.15f, 1e-6);
  const ColourGradient no_orientation = ComputeColourGradient(luv, false);
  EXPECT_TRUE(no_orientation.orientation.empty());
  EXPECT_EQ(cv::norm(no_orientation.magnitude, gradient.magnitude, cv::NORM_INF), 0.0);
}

TEST(OrientationHistograms, SplitsLinearlyBetweenNeighbouringBinsAndWraps) {
  ColourGradient gradient;
  gradient.magnitude = cv::Mat1f(1, 3, 2.f);
  gradient.orientation = cv::Mat1f(1, 3);
  gradient.orientation(0, 0) = kPi / 8;      // halfway between 0 and 45 degrees
  gradient.orientation(0, 1) = 7 * kPi / 8;  // halfway between 135 and 180 (= 0) degrees
  gradient.orientation(0, 2) = kPi / 2;      // exactly bin 2
  const auto bins = OrientationHistograms(gradient);
  EXPECT_NEAR(bins[0](0, 0), 1.f, 1e-5);
  EXPECT_NEAR(bins[1](0, 0), 1.f, 1e-5);
  EXPECT_NEAR(bins[3](0, 1), 1.f, 1e-5);
  EXPECT_NEAR(bins[0](0, 1), 1.f, 1e-5);
  EXPECT_NEAR(bins[2](0, 2), 2.f, 1e-5);
  EXPECT_NEAR(bins[1](0, 2) + bins[3](0, 2), 0.f, 1e-5);
}

TEST(EdgeChannels, HalfResolutionSizesAndVerticalStepResponse) {
  // 33 x 21 (odd: padded to 34 x 22 -> 17 x 11 cells); black left of x = 16, white from x = 16.
  cv::Mat3b image(21, 33, cv::Vec3b(0, 0, 0));
  image(cv::Rect(16, 0, 17, 21)).setTo(cv::Vec3b(255, 255, 255));
  const EdgeChannels channels = ComputeEdgeChannels(image);
  ASSERT_EQ(static_cast<int>(channels.planes.size()), kNumEdgeChannels);
  EXPECT_EQ(kNumEdgeChannels, 13);
  for (const cv::Mat1f& plane : channels.planes) {
    EXPECT_EQ(plane.size(), cv::Size(17, 11));
  }
  const int row = 5;
  const int step_cell = 8;  // covers x = 16, 17
  EXPECT_GT(channels.planes[kChanGradFull](row, step_cell), 0.1f);
  EXPECT_GT(channels.planes[kChanGradHalf](row, step_cell), 0.1f);
  EXPECT_NEAR(channels.planes[kChanGradFull](row, 1), 0.f, 1e-6);
  EXPECT_NEAR(channels.planes[kChanGradFull](row, 15), 0.f, 1e-6);
  // A vertical step has a horizontal gradient: orientation bin 0, none in bin 2.
  EXPECT_GT(channels.planes[kChanOrientFull + 0](row, step_cell), 0.1f);
  EXPECT_NEAR(channels.planes[kChanOrientFull + 2](row, step_cell), 0.f, 1e-6);
  EXPECT_NEAR(channels.planes[kChanL](row, 1), 0.f, 1e-4);
  EXPECT_NEAR(channels.planes[kChanL](row, 15), 1.f, 1e-3);
}

// The gradient rows run on OpenCV's pool: one thread and three give the same planes, bit for
// bit, and the same colour gradient.
TEST(EdgeChannels, OneThreadAndSeveralGiveTheSamePlanes) {
  cv::Mat3b image(203, 311);
  cv::RNG rng(3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  const int threads_before = cv::getNumThreads();
  cv::setNumThreads(1);
  const EdgeChannels one = ComputeEdgeChannels(image);
  const ColourGradient gradient_one = ComputeColourGradient(BgrToLuv(image), true);
  cv::setNumThreads(3);
  const EdgeChannels three = ComputeEdgeChannels(image);
  const ColourGradient gradient_three = ComputeColourGradient(BgrToLuv(image), true);
  cv::setNumThreads(threads_before);
  ASSERT_EQ(one.planes.size(), three.planes.size());
  for (size_t p = 0; p < one.planes.size(); ++p)
    EXPECT_EQ(cv::norm(one.planes[p], three.planes[p], cv::NORM_INF), 0.0) << "plane " << p;
  EXPECT_EQ(cv::norm(gradient_one.magnitude, gradient_three.magnitude, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(gradient_one.orientation, gradient_three.orientation, cv::NORM_INF), 0.0);
}

// BgrToLuv runs in bands of rows; its reference is the conversion of the whole image at once.
TEST(BgrToLuv, BandsGiveThePixelsOfOneWholeImageConversion) {
  cv::Mat3b image(150, 77);
  cv::RNG rng(5);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  cv::Mat3f unit;
  image.convertTo(unit, CV_32F, 1.0 / 255.0);
  cv::Mat3f reference;
  cv::cvtColor(unit, reference, cv::COLOR_BGR2Luv);
  reference *= 0.01f;
  const int threads_before = cv::getNumThreads();
  for (const int threads : {1, 3}) {
    cv::setNumThreads(threads);
    EXPECT_EQ(cv::norm(BgrToLuv(image), reference, cv::NORM_INF), 0.0) << threads << " threads";
  }
  cv::setNumThreads(threads_before);
}

TEST(EdgeChannels, EmptyImageGivesNoPlanes) {
  EXPECT_TRUE(ComputeEdgeChannels(cv::Mat3b()).planes.empty());
}

}  // namespace
}  // namespace tod
