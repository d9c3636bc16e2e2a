#include "core/edges/edge_labels.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace tod {

cv::Mat1b GroundTruthBoundaryPixels(const cv::Mat1i& labels) {
  cv::Mat1b boundary = cv::Mat1b::zeros(labels.size());
  for (int y = 0; y < labels.rows; ++y) {
    const int* row = labels.ptr<int>(y);
    const int* below = y + 1 < labels.rows ? labels.ptr<int>(y + 1) : nullptr;
    for (int x = 0; x < labels.cols; ++x) {
      if (row[x] == kIgnoreLabel) continue;
      if (x + 1 < labels.cols && row[x + 1] != kIgnoreLabel && row[x + 1] != row[x]) {
        boundary(y, x) = 255;
        boundary(y, x + 1) = 255;
      }
      if (below != nullptr && below[x] != kIgnoreLabel && below[x] != row[x]) {
        boundary(y, x) = 255;
        boundary(y + 1, x) = 255;
      }
    }
  }
  return boundary;
}

cv::Mat1b NearBoundaryMask(const cv::Mat1i& labels, int radius) {
  const cv::Mat1b boundary = GroundTruthBoundaryPixels(labels);
  if (radius < 1 || cv::countNonZero(boundary) == 0) return boundary;
  // Distance of every pixel to the nearest boundary pixel (distanceTransform measures to zeros).
  cv::Mat1f distance;
  cv::distanceTransform(boundary == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  // A boundary pixel's centre is half a pixel from the crack.
  const float max_distance = static_cast<float>(radius) - 0.5f + 1e-4f;
  cv::Mat1b near = distance <= max_distance;
  return near;
}

CellLabels ComputeCellLabels(const cv::Mat1i& labels, int boundary_radius, int void_window) {
  CellLabels cells;
  if (labels.empty()) return cells;
  cv::Mat1i padded;
  cv::copyMakeBorder(labels, padded, 0, labels.rows % 2, 0, labels.cols % 2, cv::BORDER_REPLICATE);
  const int cell_rows = padded.rows / 2;
  const int cell_cols = padded.cols / 2;

  cv::Mat1f near;
  NearBoundaryMask(padded, boundary_radius).convertTo(near, CV_32F, 1.0 / 255.0);
  cv::resize(near, cells.near_fraction, cv::Size(cell_cols, cell_rows), 0, 0, cv::INTER_AREA);

  cv::Mat1i void_sum;
  const cv::Mat1b is_void = (padded == kIgnoreLabel) / 255;  // 0 / 1
  cv::integral(is_void, void_sum, CV_32S);
  const int margin = std::max(void_window, 0);
  cells.void_fraction.create(cell_rows, cell_cols);
  for (int i = 0; i < cell_rows; ++i) {
    const int y0 = std::max(2 * i - margin, 0);
    const int y1 = std::min(2 * i + 2 + margin, padded.rows);
    for (int j = 0; j < cell_cols; ++j) {
      const int x0 = std::max(2 * j - margin, 0);
      const int x1 = std::min(2 * j + 2 + margin, padded.cols);
      const double sum = void_sum(y1, x1) - void_sum(y0, x1) - void_sum(y1, x0) + void_sum(y0, x0);
      cells.void_fraction(i, j) = static_cast<float>(sum / ((y1 - y0) * (x1 - x0)));
    }
  }
  return cells;
}

}  // namespace tod
