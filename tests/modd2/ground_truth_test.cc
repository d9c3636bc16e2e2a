// The geometric rules of core/modd2/modd2_ground_truth.h, each against hand-computed pixels.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/modd2/modd2_ground_truth.h"

namespace tod {
namespace {

// Mask with 255 on the 0-based inclusive rows [r0, r1] x columns [c0, c1].
cv::Mat1b Block(int width, int height, int r0, int r1, int c0, int c1) {
  cv::Mat1b m(height, width, static_cast<unsigned char>(0));
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) m(r, c) = 255;
  }
  return m;
}

int Differences(const cv::Mat1b& a, const cv::Mat1b& b) {
  EXPECT_EQ(a.size(), b.size());
  if (a.size() != b.size()) return -1;
  return cv::countNonZero(a != b);
}

TEST(FillPolygonPixelCentres, ReproducesPoly2MaskDocumentationSquare) {
  // MATLAB documentation: poly2mask([4 10 10 4], [4 4 10 10], 12, 12) sets rows and columns
  // 5..10 (1-based): centres on the left / top edge are out, on the right / bottom edge in.
  const cv::Mat1b mask = FillPolygonPixelCentres({{4, 4}, {10, 4}, {10, 10}, {4, 10}}, 12, 12);
  EXPECT_EQ(Differences(mask, Block(12, 12, 4, 9, 4, 9)), 0);
  // Vertices on the outer pixel edges (3.5, 10.5) cover rows and columns 4..10.
  const cv::Mat1b outer =
      FillPolygonPixelCentres({{3.5, 3.5}, {10.5, 3.5}, {10.5, 10.5}, {3.5, 10.5}}, 12, 12);
  EXPECT_EQ(Differences(outer, Block(12, 12, 3, 9, 3, 9)), 0);
}

TEST(FillPolygonPixelCentres, VertexOrderDoesNotMatter) {
  const cv::Mat1b cw = FillPolygonPixelCentres({{4, 4}, {10, 4}, {10, 10}, {4, 10}}, 12, 12);
  const cv::Mat1b ccw = FillPolygonPixelCentres({{4, 10}, {10, 10}, {10, 4}, {4, 4}}, 12, 12);
  EXPECT_EQ(Differences(cw, ccw), 0);
}

TEST(FillPolygonPixelCentres, TriangleByHand) {
  // Triangle (1,1), (9,1), (1,9): row r (1-based) crosses x = 1 and x = 10 - r, so columns
  // 2..10-r are inside for rows 2..8; 7 + 6 + ... + 1 = 28 pixels.
  const cv::Mat1b mask = FillPolygonPixelCentres({{1, 1}, {9, 1}, {1, 9}}, 10, 10);
  cv::Mat1b expected(10, 10, static_cast<unsigned char>(0));
  for (int r = 2; r <= 9; ++r) {
    for (int c = 2; c <= 10 - r; ++c) expected(r - 1, c - 1) = 255;
  }
  EXPECT_EQ(cv::countNonZero(expected), 28);
  EXPECT_EQ(Differences(mask, expected), 0);
}

TEST(FillPolygonPixelCentres, AgreesWithPointInPolygonOffTheBoundary) {
  // A non-convex polygon partly outside the image; every pixel centre that is not on the
  // boundary must agree with OpenCV's independent point-in-polygon test.
  const std::vector<cv::Point2d> polygon = {{-3.2, 2.7},  {14.9, 0.4}, {30.6, 9.1}, {17.3, 7.7},
                                            {21.1, 19.8}, {8.4, 13.3}, {2.2, 24.9}};
  const cv::Mat1b mask = FillPolygonPixelCentres(polygon, 25, 20);
  std::vector<cv::Point2f> contour;
  for (const cv::Point2d& p : polygon) contour.emplace_back(p);
  int checked = 0;
  for (int r = 0; r < 20; ++r) {
    for (int c = 0; c < 25; ++c) {
      const double side = cv::pointPolygonTest(contour, cv::Point2f(c + 1.f, r + 1.f), false);
      if (side == 0) continue;
      EXPECT_EQ(mask(r, c) != 0, side > 0) << "row " << r << " col " << c;
      ++checked;
    }
  }
  EXPECT_GT(checked, 400);
}

TEST(FillPolygonPixelCentres, DegenerateInputGivesEmptyMask) {
  EXPECT_EQ(cv::countNonZero(FillPolygonPixelCentres({{1, 1}, {5, 5}}, 8, 8)), 0);
  EXPECT_EQ(FillPolygonPixelCentres({}, 0, 0).total(), 0u);
}

TEST(FillPolygonPixelCentres, FarAwayVerticesCoverTheImage) {
  const double big = 1e300;
  const cv::Mat1b mask =
      FillPolygonPixelCentres({{-big, -big}, {big, -big}, {big, big}, {-big, big}}, 7, 5);
  EXPECT_EQ(cv::countNonZero(mask), 35);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(cv::countNonZero(FillPolygonPixelCentres({{nan, 1}, {5, nan}, {3, 4}}, 7, 5)), 0);
}

TEST(CleanSeaEdge, DropsNonFiniteAndClampsLikeFilterSeaEdge) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<cv::Point2d> cleaned =
      CleanSeaEdge({{-3, 4}, {nan, 7}, {5, -inf}, {10, 40}, {30, -2.5}, {inf, 3}}, 20, 12);
  ASSERT_EQ(cleaned.size(), 3u);
  EXPECT_EQ(cleaned[0], cv::Point2d(1, 4));      // x clamped up to 1
  EXPECT_EQ(cleaned[1], cv::Point2d(10, 12));    // y clamped down to the height
  EXPECT_EQ(cleaned[2], cv::Point2d(20, -2.5));  // x clamped to the width, y < 1 kept
}

TEST(Modd2WaterMask, HorizontalEdgeByHand) {
  // Edge y = 3 (1-based): the polygon (0.5,3) .. (10.5,3), (10.5,8), (0.5,8) covers rows 4..8
  // (row 3 is on its upper boundary), every column.
  const cv::Mat1b water = Modd2WaterMask({{1, 3}, {5, 3}, {10, 3}}, 10, 8);
  EXPECT_EQ(Differences(water, Block(10, 8, 3, 7, 0, 9)), 0);
}

TEST(Modd2WaterMask, SlopedEdgeByHand) {
  // Points (1,2) and (10,6.5); the first x moves to 0.5 and the last to 10.5, so the top edge
  // runs from (0.5,2) to (10.5,6.5): y = 2 + 0.45 (x - 0.5). A centre (c, r) is water when
  // r > 2 + 0.45 (c - 0.5) (no centre lies exactly on that line).
  const cv::Mat1b water = Modd2WaterMask({{1, 2}, {10, 6.5}}, 10, 10);
  cv::Mat1b expected(10, 10, static_cast<unsigned char>(0));
  for (int r = 1; r <= 10; ++r) {
    for (int c = 1; c <= 10; ++c) {
      if (r > 2 + 0.45 * (c - 0.5)) expected(r - 1, c - 1) = 255;
    }
  }
  EXPECT_EQ(Differences(water, expected), 0);
  EXPECT_EQ(water(1, 0), 0);    // row 2, column 1: y line 2.225 > 2
  EXPECT_EQ(water(2, 0), 255);  // row 3, column 1
}

TEST(Modd2WaterMask, DropsPointsBelowZeroAndEmptyEdge) {
  // (5,-4) has y < 0 and is dropped: the water is then the flat edge y = 3.
  const cv::Mat1b water = Modd2WaterMask({{1, 3}, {5, -4}, {10, 3}}, 10, 8);
  EXPECT_EQ(Differences(water, Block(10, 8, 3, 7, 0, 9)), 0);
  EXPECT_EQ(cv::countNonZero(Modd2WaterMask({}, 10, 8)), 0);
  EXPECT_EQ(cv::countNonZero(Modd2WaterMask({{4, -1}}, 10, 8)), 0);
}

TEST(Modd2AboveSeaEdgeMask, HorizontalEdgeByHand) {
  // Polygon (1,1), (1,3), (5,3), (10,3), (10,1): rows 2..3 and columns 2..10 (1-based); row 1 and
  // column 1 lie on its upper / left boundary.
  const cv::Mat1b above = Modd2AboveSeaEdgeMask({{1, 3}, {5, 3}, {10, 3}}, 10, 8);
  EXPECT_EQ(Differences(above, Block(10, 8, 1, 2, 1, 9)), 0);
}

TEST(RoundModd2Box, RoundsClampsAndCoversWPlusOneColumns) {
  // [2.5 6.2 5.4 5.49] -> x 3, y 6, w 5, h 5: columns 3..8, rows 6..11 (1-based).
  Modd2PixelBox b = RoundModd2Box({2.5, 6.2, 5.4, 5.49}, 20, 12);
  ASSERT_TRUE(b.valid);
  EXPECT_EQ(b.pixels, (Box{2, 5, 6, 6}));
  EXPECT_EQ(b.official_area, 25);
  // Past the border: w capped at 20 - 15, h at 12 - 7.
  b = RoundModd2Box({15.2, 6.5, 30, 7}, 20, 12);
  EXPECT_EQ(b.pixels, (Box{14, 6, 6, 6}));
  EXPECT_EQ(b.official_area, 25);
  // Left / above the image: x, y clamped to 1, extents kept.
  b = RoundModd2Box({-4.6, 0.2, 3, 2}, 20, 12);
  EXPECT_EQ(b.pixels, (Box{0, 0, 4, 3}));
  EXPECT_EQ(b.official_area, 6);
  // x beyond the width: clamped to the last column, which alone remains.
  b = RoundModd2Box({25, 3, 4, 0.4}, 20, 12);
  EXPECT_EQ(b.pixels, (Box{19, 2, 1, 1}));
  EXPECT_EQ(b.official_area, 0);
  // Negative rounded extent or non-finite input: no pixels.
  EXPECT_FALSE(RoundModd2Box({3, 3, -2, 4}, 20, 12).valid);
  EXPECT_FALSE(RoundModd2Box({std::nan(""), 3, 2, 4}, 20, 12).valid);
  EXPECT_TRUE(RoundModd2Box({1e300, 1e300, 1e300, 1e300}, 20, 12).valid);
}

TEST(Modd2Freezone, RowsAboveTheFirstChangePerColumn) {
  cv::Mat1b water(6, 3, static_cast<unsigned char>(0));
  water.col(0).rowRange(3, 6).setTo(255);  // change between rows 2 and 3 -> rows 0..2
  water.col(1).setTo(255);                 // never changes -> row 0 only
  // column 2 all land: never changes -> row 0 only
  const cv::Mat1b freezone = Modd2Freezone(water);
  cv::Mat1b expected(6, 3, static_cast<unsigned char>(0));
  expected.col(0).rowRange(0, 3).setTo(255);
  expected(0, 1) = 255;
  expected(0, 2) = 255;
  EXPECT_EQ(Differences(freezone, expected), 0);
}

}  // namespace
}  // namespace tod
