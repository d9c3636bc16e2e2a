// The run-based connected-component labelling of the sticky superpixels against a per-pixel
// flood fill (the implementation it replaced), on maps built to stress it.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <vector>

#include "core/edges/superpixel_boundaries.h"

namespace tod {
namespace {

// 4-connected components numbered 1.. in raster order of first appearance (flood fill).
cv::Mat1i ReferenceComponents(const cv::Mat1i& labels, int* count) {
  cv::Mat1i out(labels.size(), 0);
  *count = 0;
  std::vector<cv::Point> stack;
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      if (out(y, x) != 0) continue;
      out(y, x) = ++*count;
      stack.push_back({x, y});
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        for (const cv::Point d :
             {cv::Point(-1, 0), cv::Point(1, 0), cv::Point(0, -1), cv::Point(0, 1)}) {
          const cv::Point q = p + d;
          if (q.x < 0 || q.y < 0 || q.x >= labels.cols || q.y >= labels.rows) continue;
          if (out(q) != 0 || labels(q) != labels(p)) continue;
          out(q) = *count;
          stack.push_back(q);
        }
      }
    }
  }
  return out;
}

// Random map of a few labels painted as rectangles, diagonal staircases and single pixels:
// many components, U shapes that merge late, and diagonal-only contacts.
cv::Mat1i RandomLabels(int width, int height, int num_labels, cv::RNG& rng) {
  cv::Mat1i labels(height, width, 0);
  for (int s = 0; s < 3 * (width + height); ++s) {
    const int label = rng.uniform(0, num_labels);
    const int shape = rng.uniform(0, 3);
    const int x0 = rng.uniform(0, width);
    const int y0 = rng.uniform(0, height);
    if (shape == 0) {
      const int x1 = std::min(width, x0 + rng.uniform(1, 8));
      const int y1 = std::min(height, y0 + rng.uniform(1, 8));
      labels(cv::Range(y0, y1), cv::Range(x0, x1)).setTo(label);
    } else if (shape == 1) {
      for (int k = 0; k < 6 && x0 + k < width && y0 + k < height; ++k) {
        labels(y0 + k, x0 + k) = label;  // touches itself only diagonally
      }
    } else {
      labels(y0, x0) = label;
    }
  }
  return labels;
}

TEST(RelabelConnectedComponentsTest, MatchesFloodFillOnRandomMaps) {
  cv::RNG rng(7);
  const std::vector<cv::Size> sizes = {{1, 1},  {1, 17}, {23, 1},  {2, 2},
                                       {5, 40}, {37, 3}, {64, 48}, {129, 77}};
  for (const cv::Size size : sizes) {
    for (int trial = 0; trial < 20; ++trial) {
      const int num_labels = 1 + trial % 4;  // 1 label: one component; more: many
      cv::Mat1i labels = RandomLabels(size.width, size.height, num_labels, rng);
      int expected_count = 0;
      const cv::Mat1i expected = ReferenceComponents(labels, &expected_count);
      const int count = RelabelConnectedComponents(labels);
      ASSERT_EQ(count, expected_count) << size << " trial " << trial;
      ASSERT_EQ(cv::countNonZero(labels != expected), 0) << size << " trial " << trial;
    }
  }
}

TEST(RelabelConnectedComponentsTest, DiagonalContactDoesNotConnect) {
  cv::Mat1i labels = (cv::Mat1i(3, 3) << 5, 0, 5, 0, 5, 0, 5, 0, 5);
  // The 5s and the 0s alike touch their kind only diagonally: nine components.
  EXPECT_EQ(RelabelConnectedComponents(labels), 9);
  const cv::Mat1i expected = (cv::Mat1i(3, 3) << 1, 2, 3, 4, 5, 6, 7, 8, 9);
  EXPECT_EQ(cv::countNonZero(labels != expected), 0);
}

}  // namespace
}  // namespace tod
