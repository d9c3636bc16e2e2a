#include <gtest/gtest.h>

#include "core/proposals/edge_box_scorer.h"

namespace tod {
namespace {

TEST(ClearCropBorderEdgesTest, RemovesFrameLineKeepsPerpendicularContour) {
  cv::Mat1f map(20, 20, 0.f);
  map.col(0).setTo(0.7f);                           // frame line along the left border
  for (int y = 0; y <= 8; ++y) map(y, 10) = 1.f;    // contour meeting the top border at x = 10
  for (int x = 12; x <= 19; ++x) map(14, x) = 1.f;  // contour meeting the right border
  ClearCropBorderEdges(map);
  EXPECT_EQ(cv::countNonZero(map.col(0)), 0);
  EXPECT_EQ(map(0, 10), 1.f);
  EXPECT_EQ(map(1, 10), 1.f);
  EXPECT_EQ(map(14, 19), 1.f);
  EXPECT_EQ(cv::countNonZero(map), 9 + 8);
}

TEST(ClearCropBorderEdgesTest, RemovesTwoPixelFrameAlongTheBottom) {
  cv::Mat1f map(10, 12, 0.f);
  map.row(9).setTo(1.f);
  map.row(8).setTo(1.f);
  ClearCropBorderEdges(map);
  // Bottom row, columns 0..10: inward neighbour, next border pixel and its inward neighbour are
  // all set -> cleared. Column 11 has no next pixel, and on the right column its next pixel
  // down does not exist while its inward neighbour is set -> it survives.
  EXPECT_EQ(cv::countNonZero(map.row(9)), 1);
  EXPECT_EQ(map(9, 11), 1.f);
  // Row 8 is not on the border except its two ends: (8, 0) has inward (8, 1) set and the next
  // pixel down (9, 0) and (9, 1) set -> cleared; (8, 11) likewise.
  EXPECT_EQ(map(8, 0), 0.f);
  EXPECT_EQ(map(8, 11), 0.f);
  EXPECT_EQ(cv::countNonZero(map.row(8)), 10);
}

TEST(ClearCropBorderEdgesTest, DegenerateMaps) {
  cv::Mat1f empty;
  ClearCropBorderEdges(empty);
  EXPECT_TRUE(empty.empty());
  cv::Mat1f one(1, 1, 1.f);
  ClearCropBorderEdges(one);  // no inward neighbour: a border run
  EXPECT_EQ(one(0, 0), 0.f);
  cv::Mat1f zero(5, 5, 0.f);
  ClearCropBorderEdges(zero);
  EXPECT_EQ(cv::countNonZero(zero), 0);
}

}  // namespace
}  // namespace tod
