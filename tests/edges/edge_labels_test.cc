#include "core/edges/edge_labels.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

// 8 x 8: columns 0..3 label 0, columns 4..7 label 2; the crack runs between x = 3 and x = 4.
cv::Mat1i TwoHalves() {
  cv::Mat1i labels = cv::Mat1i::zeros(8, 8);
  labels(cv::Rect(4, 0, 4, 8)).setTo(2);
  return labels;
}

TEST(GroundTruthBoundary, MarksBothPixelsOfADifferingPair) {
  const cv::Mat1b boundary = GroundTruthBoundaryPixels(TwoHalves());
  for (int x = 0; x < 8; ++x) {
    EXPECT_EQ(boundary(5, x), (x == 3 || x == 4) ? 255 : 0) << "x = " << x;
  }
  EXPECT_EQ(cv::countNonZero(boundary), 16);
}

TEST(GroundTruthBoundary, VoidNeighboursMakeNoBoundary) {
  cv::Mat1i labels = TwoHalves();
  labels(cv::Rect(0, 0, 8, 4)).setTo(kIgnoreLabel);  // top half void
  const cv::Mat1b boundary = GroundTruthBoundaryPixels(labels);
  // Only the 0 | 2 crack in rows 4..7 remains; the void | label row change is not a boundary.
  EXPECT_EQ(cv::countNonZero(boundary), 8);
  EXPECT_EQ(boundary(3, 3), 0);
  EXPECT_EQ(boundary(4, 3), 255);
}

TEST(NearBoundary, RadiusTwoReachesOneAndAHalfPixelsFromBoundaryPixels) {
  const cv::Mat1b near = NearBoundaryMask(TwoHalves(), 2);
  // Pixel centres at distance 0.5 (x = 3, 4) and 1.5 (x = 2, 5) from the crack are within 2.
  for (int x = 0; x < 8; ++x) {
    EXPECT_EQ(near(2, x), (x >= 2 && x <= 5) ? 255 : 0) << "x = " << x;
  }
  const cv::Mat1b one = NearBoundaryMask(TwoHalves(), 1);
  EXPECT_EQ(cv::countNonZero(one), 16);
  EXPECT_EQ(cv::countNonZero(NearBoundaryMask(cv::Mat1i::zeros(4, 4), 2)), 0);
}

TEST(CellLabels, NearAndVoidFractionsPerTwoByTwoCell) {
  cv::Mat1i labels = TwoHalves();
  labels(cv::Rect(0, 0, 8, 2)).setTo(kIgnoreLabel);  // rows 0, 1 void
  const CellLabels cells = ComputeCellLabels(labels, 2, /*void_window=*/0);
  ASSERT_EQ(cells.near_fraction.size(), cv::Size(4, 4));
  // Row of cells 2 (pixel rows 4, 5): near columns 2..5 -> cells 1 and 2 fully near.
  EXPECT_FLOAT_EQ(cells.near_fraction(2, 0), 0.f);
  EXPECT_FLOAT_EQ(cells.near_fraction(2, 1), 1.f);
  EXPECT_FLOAT_EQ(cells.near_fraction(2, 2), 1.f);
  EXPECT_FLOAT_EQ(cells.near_fraction(2, 3), 0.f);
  EXPECT_FLOAT_EQ(cells.void_fraction(0, 1), 1.f);
  EXPECT_FLOAT_EQ(cells.void_fraction(1, 1), 0.f);
  // Window margin 1: cell row 1 sees pixel rows 1..4, of which row 1 is void -> 1/4.
  const CellLabels wide = ComputeCellLabels(labels, 2, /*void_window=*/1);
  EXPECT_FLOAT_EQ(wide.void_fraction(1, 1), 0.25f);
}

TEST(CellLabels, OddSizeIsPaddedByReplication) {
  const CellLabels cells = ComputeCellLabels(cv::Mat1i::zeros(5, 7), 2);
  EXPECT_EQ(cells.near_fraction.size(), cv::Size(4, 3));
  EXPECT_EQ(cells.void_fraction.size(), cv::Size(4, 3));
}

}  // namespace
}  // namespace tod
