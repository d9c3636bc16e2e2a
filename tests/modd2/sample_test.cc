// SampleFromModd2Annotation: road / obstacle / ignore and instances, pixel for pixel.
#include <gtest/gtest.h>

#include <limits>

#include "core/modd2/modd2_reader.h"

namespace tod {
namespace {

cv::Mat1b Rects(int width, int height, const std::vector<cv::Rect>& rects) {
  cv::Mat1b m(height, width, static_cast<unsigned char>(0));
  for (const cv::Rect& r : rects) m(r).setTo(255);
  return m;
}

int Differences(const cv::Mat1b& a, const cv::Mat1b& b) { return cv::countNonZero(a != b); }

// 20 x 12 image, sea edge y = 4 (1-based) after cleaning: water = 0-based rows 4..11.
// Above-edge mask: 0-based rows 1..3, columns 1..19.
Modd2Annotation FourBoxes() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Modd2Annotation a;
  a.sea_edge = {{-3, 4}, {nan, 7}, {10, 4}, {30, 4}, {inf, 2}};
  a.obstacles = {
      {2.5, 6.2, 5.4, 5.49},  // A: cols 3..8, rows 6..11; w*h = 25 -> kept small
      {11, 9, 2, 8},          // B: h capped to 3; w*h = 6 < 25 -> dropped (ignore)
      {9, 2.6, 3, 3},         // C: rows 3..6 reach above the edge -> large (cut from water)
      {15.2, 6.5, 30, 7},     // D: past the right / bottom border, capped to 5 x 5 -> kept
  };
  return a;
}

TEST(SampleFromModd2Annotation, MasksAndInstancesByHand) {
  const cv::Mat3b image(12, 20, cv::Vec3b(10, 20, 30));
  const Sample s = SampleFromModd2Annotation(FourBoxes(), image, "frame", 25);
  EXPECT_EQ(s.name, "frame");
  ASSERT_EQ(s.image.size(), image.size());

  const cv::Rect a(2, 5, 6, 6), b(10, 8, 3, 4), c(8, 2, 4, 4), d(14, 6, 6, 6);
  const cv::Mat1b water = Rects(20, 12, {cv::Rect(0, 4, 20, 8)});
  const cv::Mat1b boxes = Rects(20, 12, {a, b, c, d});
  const cv::Mat1b expected_road = water & ~boxes;
  const cv::Mat1b expected_obstacle = Rects(20, 12, {a, d});
  const cv::Mat1b expected_ignore = ~(expected_road | expected_obstacle);

  EXPECT_EQ(Differences(s.road, expected_road), 0);
  EXPECT_EQ(Differences(s.obstacle, expected_obstacle), 0);
  EXPECT_EQ(Differences(s.ignore, expected_ignore), 0);
  // 160 water pixels minus A (36), B (12), C's two water rows (8) and D (36).
  EXPECT_EQ(cv::countNonZero(s.road), 68);
  EXPECT_EQ(cv::countNonZero(s.obstacle), 72);
  EXPECT_EQ(cv::countNonZero(s.ignore), 240 - 68 - 72);

  ASSERT_EQ(s.instances.size(), 2u);
  EXPECT_EQ(s.instances[0].id, 1);
  EXPECT_EQ(s.instances[0].box, (Box{2, 5, 6, 6}));
  EXPECT_EQ(s.instances[0].pixel_count(), 36);
  EXPECT_EQ(s.instances[1].id, 4);
  EXPECT_EQ(s.instances[1].box, (Box{14, 6, 6, 6}));
  EXPECT_EQ(s.instances[1].mask.size(), cv::Size(6, 6));
}

TEST(SampleFromModd2Annotation, MinObstacleAreaIsAParameter) {
  const cv::Mat3b image(12, 20, cv::Vec3b(0, 0, 0));
  // With a threshold of 6, B (w*h = 6) is kept as well; with 26, A and D (25) are dropped.
  EXPECT_EQ(SampleFromModd2Annotation(FourBoxes(), image, "f", 6).instances.size(), 3u);
  const Sample strict = SampleFromModd2Annotation(FourBoxes(), image, "f", 26);
  EXPECT_TRUE(strict.instances.empty());
  EXPECT_EQ(cv::countNonZero(strict.obstacle), 0);
  EXPECT_EQ(cv::countNonZero(strict.road), 68);  // dropped boxes stay out of the road
}

TEST(SampleFromModd2Annotation, SmallBoxAboveTheWaterIsDroppedByTheFreezone) {
  // Sea edge (1,6), (10,-5), (20,6): the above-edge mask follows the V (the point above the
  // image stays), while the water drops the y < 0 point and starts below y = 6. A 25 px box at
  // columns 7..12, rows 3..8 misses the V (row 3 reaches only columns <= 3 and >= 18) so it is
  // small, but its top corners are above the water: the official freezone rule removes it.
  Modd2Annotation a;
  a.sea_edge = {{1, 6}, {10, -5}, {20, 6}};
  a.obstacles = {{7, 3, 5, 5}};
  const cv::Mat3b image(12, 20, cv::Vec3b(0, 0, 0));
  const Sample s = SampleFromModd2Annotation(a, image, "f", 25);
  EXPECT_TRUE(s.instances.empty());
  const cv::Mat1b expected_road =
      Rects(20, 12, {cv::Rect(0, 6, 20, 6)}) & ~Rects(20, 12, {cv::Rect(6, 2, 6, 6)});
  EXPECT_EQ(Differences(s.road, expected_road), 0);
  // The same box lower down, fully on the water, is kept.
  a.obstacles = {{7, 7, 5, 4}, {7, 7, 5, 5}};  // w*h = 20 (dropped) and 25 (kept)
  const Sample lower = SampleFromModd2Annotation(a, image, "f", 25);
  ASSERT_EQ(lower.instances.size(), 1u);
  EXPECT_EQ(lower.instances[0].id, 2);
  EXPECT_EQ(lower.instances[0].box, (Box{6, 6, 6, 6}));
}

TEST(SampleFromModd2Annotation, NoSeaEdgeMeansNoWater) {
  Modd2Annotation a;
  a.obstacles = {{3, 3, 6, 6}};
  const cv::Mat3b image(12, 20, cv::Vec3b(0, 0, 0));
  const Sample s = SampleFromModd2Annotation(a, image, "f", 25);
  EXPECT_EQ(cv::countNonZero(s.road), 0);
  // No edge: nothing is above it either, so the box is small; its corners are in the freezone
  // only at row 0, which it does not touch: kept.
  ASSERT_EQ(s.instances.size(), 1u);
  EXPECT_EQ(s.instances[0].box, (Box{2, 2, 7, 7}));
}

}  // namespace
}  // namespace tod
