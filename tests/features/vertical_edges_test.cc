#include "core/features/vertical_edges.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/features/box_features.h"

namespace tod {
namespace {

// A grey image as BGR.
cv::Mat3b AsBgr(const cv::Mat1b& grey) {
  cv::Mat3b bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

// Dark with a bright bar of `width` px rotated by `degrees` from vertical through the centre.
cv::Mat3b Bar(int size, double degrees, int width) {
  cv::Mat1b grey(size, size, uchar{40});
  const double t = degrees * CV_PI / 180.0;
  const cv::Point2d centre(size / 2.0, size / 2.0), along(std::sin(t), -std::cos(t));
  cv::line(grey, centre - along * size, centre + along * size, cv::Scalar(220), width, cv::LINE_8);
  return AsBgr(grey);
}

// 3 x 3 Sobel written out on the grey image, the border reflected without repeating the edge
// pixel; calls visit(gx, gy, magnitude) for every pixel of a crop-local rectangle.
template <typename Visit>
void ForEachGradient(const cv::Mat3b& bgr, const cv::Rect& rect, Visit visit) {
  cv::Mat1b grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  const auto at = [&grey](int y, int x) {
    const auto reflect = [](int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); };
    return static_cast<float>(grey(reflect(y, grey.rows), reflect(x, grey.cols)));
  };
  for (int y = rect.y; y < rect.y + rect.height; ++y)
    for (int x = rect.x; x < rect.x + rect.width; ++x) {
      const float gx = (at(y - 1, x + 1) + 2 * at(y, x + 1) + at(y + 1, x + 1)) -
                       (at(y - 1, x - 1) + 2 * at(y, x - 1) + at(y + 1, x - 1));
      const float gy = (at(y + 1, x - 1) + 2 * at(y + 1, x) + at(y + 1, x + 1)) -
                       (at(y - 1, x - 1) + 2 * at(y - 1, x) + at(y - 1, x + 1));
      visit(gx, gy, std::hypot(gx, gy));  // in float, as the tables
    }
}

// The definition of vertical_edges.h, pixel by pixel, over a crop-local rectangle.
double BruteForceShare(const cv::Mat3b& bgr, const cv::Rect& rect,
                       const VerticalEdgeParams& params = {}) {
  double vertical = 0, counted = 0;
  ForEachGradient(bgr, rect, [&](float, float gy, double m) {
    if (m < params.min_gradient) return;
    counted += m;
    const double tilt = std::asin(std::min(1.0, std::abs(gy) / m)) * 180.0 / CV_PI;
    if (tilt < params.max_tilt_degrees) vertical += m;
  });
  return counted > 0 ? vertical / counted : 0.0;
}

TEST(VerticalEdgeIntegrals, UprightBarsAreVerticalLyingAndSlantedBarsAreNot) {
  const cv::Rect all(0, 0, 64, 64);
  EXPECT_NEAR(VerticalEdgeIntegrals(Bar(64, 0, 9), {0, 0}).Share(all), 1.0, 1e-9);
  EXPECT_NEAR(VerticalEdgeIntegrals(Bar(64, 90, 9), {0, 0}).Share(all), 0.0, 1e-9);
  // A stripe slanted as lane paint is in perspective (30-60 degrees) is not vertical, except
  // where its line steps, a pixel here and there.
  EXPECT_LT(VerticalEdgeIntegrals(Bar(64, 35, 9), {0, 0}).Share(all), 0.15);
  EXPECT_LT(VerticalEdgeIntegrals(Bar(64, 55, 9), {0, 0}).Share(all), 0.15);
  // Flat or faint: nothing counts.
  EXPECT_EQ(
      VerticalEdgeIntegrals(AsBgr(cv::Mat1b(32, 32, uchar{90})), {0, 0}).Share({0, 0, 32, 32}),
      0.0);
  cv::Mat1b faint(32, 32, uchar{90});
  faint.colRange(16, 32).setTo(95);  // a 5-level step: Sobel 20 < 40
  EXPECT_EQ(VerticalEdgeIntegrals(AsBgr(faint), {0, 0}).Share({0, 0, 32, 32}), 0.0);
}

TEST(VerticalEdgeIntegrals, EveryRectangleMatchesThePixelDefinition) {
  std::mt19937 rng(5);
  cv::Mat1b grey(90, 120);
  cv::randu(grey, 0, 256);
  cv::GaussianBlur(grey, grey, cv::Size(5, 5), 1.2);
  for (int i = 0; i < 12; ++i)  // some strong edges of every orientation
    cv::line(grey, {static_cast<int>(rng() % 120), static_cast<int>(rng() % 90)},
             {static_cast<int>(rng() % 120), static_cast<int>(rng() % 90)},
             cv::Scalar(static_cast<int>(rng() % 256)), 3);
  const cv::Mat3b bgr = AsBgr(grey);
  const VerticalEdgeIntegrals table(bgr, {300, 200});
  EXPECT_EQ(table.size(), bgr.size());
  EXPECT_EQ(table.origin(), cv::Point(300, 200));
  for (int i = 0; i < 200; ++i) {
    const int x = rng() % 120, y = rng() % 90;
    const cv::Rect r(x, y, 1 + rng() % (120 - x), 1 + rng() % (90 - y));
    EXPECT_NEAR(table.Share(r), BruteForceShare(bgr, r), 1e-9) << r;
  }
}

TEST(VerticalEdgeIntegrals, SameTablesOnAnyThreadCount) {
  cv::Mat1b grey(300, 200);
  cv::randu(grey, 0, 256);
  const cv::Mat3b bgr = AsBgr(grey);
  const int before = cv::getNumThreads();
  cv::setNumThreads(1);
  const VerticalEdgeIntegrals one(bgr, {0, 0});
  cv::setNumThreads(4);
  const VerticalEdgeIntegrals four(bgr, {0, 0});
  cv::setNumThreads(before);
  for (const cv::Rect r :
       {cv::Rect(0, 0, 200, 300), cv::Rect(13, 70, 50, 31), cv::Rect(199, 0, 1, 300)}) {
    EXPECT_EQ(one.Share(r), four.Share(r)) << r;
  }
}

// Feature 21 in the extractor: the table's share of the clipped box, 21 columns with the option,
// 20 without; the shared form needs the frame's table.
TEST(VerticalEdgeFeature, TwentyFirstColumnIsTheBoxsVerticalShare) {
  const cv::Mat3b bgr = Bar(64, 0, 9);
  const cv::Mat1f map(64, 64, 0.f);
  BoxFeatureOptions options;
  options.vertical_edges = true;
  const BoxFeatureExtractor own(map, bgr, {0, 0}, {64, 64}, options);
  ASSERT_TRUE(own.status().ok()) << own.status().message();
  const std::vector<ScoredBox> boxes = {{{20, 10, 24, 30}, 0.5f}, {{0, 0, 10, 10}, 0.1f}};
  const cv::Mat1f rows = own.ComputeAll(boxes);
  ASSERT_EQ(rows.cols, 21);
  EXPECT_FLOAT_EQ(rows(0, 20), 1.f);  // the bar's two sides
  EXPECT_FLOAT_EQ(rows(1, 20), 0.f);  // flat corner
  EXPECT_EQ(BoxFeatureExtractor(map, bgr, {0, 0}, {64, 64}).ComputeAll(boxes).cols, 20);

  // Shared tables of a larger crop: the same value for a box inside the region.
  cv::Mat3b frame(100, 120, cv::Vec3b(40, 40, 40));
  bgr.copyTo(frame(cv::Rect(30, 20, 64, 64)));
  const auto colour = std::make_shared<const ColourIntegrals>(frame, cv::Point(0, 0));
  const auto vertical = std::make_shared<const VerticalEdgeIntegrals>(frame, cv::Point(0, 0));
  const cv::Mat1f region_map(50, 60, 0.f);
  const BoxFeatureExtractor shared(colour, region_map, {40, 25}, frame.size(), options, vertical);
  ASSERT_TRUE(shared.status().ok()) << shared.status().message();
  const Box box{50, 30, 24, 30};
  const cv::Rect in_frame(50, 30, 24, 30);
  EXPECT_FLOAT_EQ(shared.Compute(box, 0.f)[20],
                  static_cast<float>(BruteForceShare(frame, in_frame)));
  const BoxFeatureExtractor missing(colour, region_map, {40, 25}, frame.size(), options);
  EXPECT_FALSE(missing.status().ok());
  EXPECT_NE(missing.status().message().find("vertical"), std::string::npos);
  const auto small =
      std::make_shared<const VerticalEdgeIntegrals>(frame(cv::Rect(0, 0, 50, 50)), cv::Point(0, 0));
  EXPECT_FALSE(BoxFeatureExtractor(colour, region_map, {40, 25}, frame.size(), options, small)
                   .status()
                   .ok());
}

}  // namespace
}  // namespace tod
