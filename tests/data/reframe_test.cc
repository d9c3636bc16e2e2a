#include "core/data/reframe.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

// Rows numbered by their value, so where each row went is readable off the result.
cv::Mat1b RowIndexImage(int width, int height) {
  cv::Mat1b image(height, width);
  for (int y = 0; y < height; ++y) image.row(y).setTo(y);
  return image;
}

TEST(ReframeTest, ShiftUpMovesRowsUpAndVoidsTheUncoveredLabels) {
  const cv::Mat1b labels = RowIndexImage(8, 100);
  const cv::Mat moved = Reframe(labels, {.shift_up = 0.1}, ReframeKind::kLabels);
  ASSERT_EQ(moved.size(), labels.size());
  EXPECT_EQ(moved.at<uchar>(0, 3), 10);    // row 10 is now at the top
  EXPECT_EQ(moved.at<uchar>(89, 3), 99);   // the last real row
  EXPECT_EQ(moved.at<uchar>(90, 3), 255);  // uncovered: void
  EXPECT_EQ(moved.at<uchar>(99, 3), 255);

  const cv::Mat image = Reframe(labels, {.shift_up = 0.1}, ReframeKind::kImage);
  EXPECT_EQ(image.at<uchar>(99, 3), 99) << "the image repeats its edge row";
  const cv::Mat down = Reframe(labels, {.shift_up = -0.2}, ReframeKind::kLabels);
  EXPECT_EQ(down.at<uchar>(19, 0), 255);
  EXPECT_EQ(down.at<uchar>(20, 0), 0);
  EXPECT_EQ(down.at<uchar>(99, 0), 79);
}

TEST(ReframeTest, ScaleThenCentreCrop) {
  const cv::Mat1b labels = RowIndexImage(200, 100);
  const cv::Mat half = Reframe(labels, {.scale = 0.5}, ReframeKind::kLabels);
  EXPECT_EQ(half.size(), cv::Size(100, 50));
  EXPECT_EQ(half.at<uchar>(10, 0), 20) << "nearest neighbour keeps label values";
  const cv::Mat cropped = Reframe(labels, {.crop = {120, 60}}, ReframeKind::kLabels);
  EXPECT_EQ(cropped.size(), cv::Size(120, 60));
  EXPECT_EQ(cropped.at<uchar>(0, 0), 20);  // (100 - 60) / 2 rows cut above
  const cv::Mat wide = Reframe(labels, {.crop = {120, 0}}, ReframeKind::kLabels);
  EXPECT_EQ(wide.size(), cv::Size(120, 100));
  EXPECT_TRUE(Reframe(labels, {.crop = {300, 0}}, ReframeKind::kLabels).empty());
}

TEST(ReframeTest, ImagesAreResampledNotPicked) {
  cv::Mat3b stripes(4, 4, cv::Vec3b(0, 0, 0));
  stripes.row(1).setTo(cv::Vec3b(200, 200, 200));
  stripes.row(3).setTo(cv::Vec3b(200, 200, 200));
  const cv::Mat3b half = Reframe(stripes, {.scale = 0.5}, ReframeKind::kImage);
  ASSERT_EQ(half.size(), cv::Size(2, 2));
  EXPECT_EQ(half(0, 0)[0], 100) << "area resampling averages the two rows";
}

}  // namespace
}  // namespace tod
