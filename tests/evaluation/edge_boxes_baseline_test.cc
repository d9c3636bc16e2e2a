#include "core/evaluation/edge_boxes_baseline.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

TEST(ThinEdges, KeepsTheRidgeOfAThickVerticalEdge) {
  cv::Mat1f edge(5, 7, 0.f);
  edge.col(2).setTo(0.5f);
  edge.col(3).setTo(1.0f);
  edge.col(4).setTo(0.5f);
  // Orientation of a vertical edge: theta = pi / 2 (the edge runs along y).
  const cv::Mat1f theta(edge.size(), static_cast<float>(CV_PI / 2));
  const cv::Mat1f thin = ThinEdges(edge, theta);
  for (int y = 0; y < 5; ++y) {
    EXPECT_FLOAT_EQ(thin(y, 3), 1.0f);
    EXPECT_FLOAT_EQ(thin(y, 2), 0.f);
    EXPECT_FLOAT_EQ(thin(y, 4), 0.f);
  }
}

TEST(EdgeBoxesBaseline, FindsAnIsolatedSquareAndOffsetsByR1) {
  cv::Mat1f edge(120, 160, 0.f);
  cv::rectangle(edge, cv::Rect(60, 40, 30, 30), cv::Scalar(1.0), 1);
  const Box r1{100, 200, 160, 120};
  const std::vector<Box> boxes = EdgeBoxesBaseline(edge, r1, 50);
  ASSERT_FALSE(boxes.empty());
  double best = 0;
  for (std::size_t i = 0; i < std::min<std::size_t>(5, boxes.size()); ++i)
    best = std::max(best, BoxIoU(boxes[i], Box{160, 240, 31, 31}));
  EXPECT_GT(best, 0.6);
}

}  // namespace
}  // namespace tod
