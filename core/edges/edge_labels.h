// Training labels of the pixel edge classifier (ALGORITHM.md §3.4, "Preferred pipeline" step 1):
// a ground-truth boundary is a change of label between 4-neighbours where neither side is void.
#pragma once

#include <opencv2/core.hpp>

namespace tod {

inline constexpr int kIgnoreLabel = -1;

// 255 on both pixels of every 4-neighbour pair whose labels differ and are both != -1; the
// boundary itself runs on the crack between them, half a pixel from each.
cv::Mat1b GroundTruthBoundaryPixels(const cv::Mat1i& labels);

// 255 where the pixel centre lies within `radius` px (Euclidean) of a ground-truth boundary crack,
// i.e. within radius - 0.5 of a boundary pixel. radius < 1 marks the boundary pixels only.
cv::Mat1b NearBoundaryMask(const cv::Mat1i& labels, int radius);

// Per cell of the half-resolution grid (see edge_channels.h; odd sizes padded by replication):
// the fraction of the cell's 2x2 pixels that are near a boundary and the fraction of void pixels
// in the (2 * void_window + 2)^2 full-resolution window centred on the cell.
struct CellLabels {
  cv::Mat1f near_fraction;
  cv::Mat1f void_fraction;
};
CellLabels ComputeCellLabels(const cv::Mat1i& labels, int boundary_radius, int void_window = 2);

}  // namespace tod
