// Pairs of adjacent superpixels and the features the occlusion classifier sees for each pair
// (ALGORITHM.md §3.4 step 4). Shared by training and painting so both see identical features.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/edges/sticky_superpixels.h"

namespace tod {

// Feature columns, in order.
enum OcclusionFeature : int {
  kEdgeMean = 0,         // mean Ê along the shared boundary
  kEdgeMax,              // max Ê along it
  kEdgeMedian,           // median Ê along it
  kBoundaryLength,       // number of boundary pixels shared by the pair
  kBoundaryOrientation,  // principal direction of the boundary pixels, radians from horizontal
                         // in [0, π/2]
  kBoundaryY,            // mean boundary row / crop height
  kAreaSmaller,          // pixel count of the smaller region
  kAreaLarger,           // pixel count of the larger region
  kLuvDiffL,             // |ΔL| of the region means (OpenCV 8-bit LUV scale)
  kLuvDiffU,             // |Δu|
  kLuvDiffV,             // |Δv|
  kLuvDiffNorm,          // Euclidean norm of the LUV mean difference
  kHueChi2,              // χ² distance of the regions' 16-bin hue histograms
  kSaturationChi2,       // ... saturation
  kValueChi2,            // ... value
  kTextureChi2,    // χ² distance of 8-bin magnitude-weighted gradient-orientation histograms
  kVerticalOrder,  // (centroid row of smaller − centroid row of larger) / crop height:
                   // negative when the smaller region sits above the larger one
  kNumOcclusionFeatures
};

// Sizes are in pixels (kVerticalOrder over the crop height), as §3.4; over the rows below a
// horizon they were measured and removed (docs/findings.md#occlusion-size-features).
struct SuperpixelPairs {
  std::vector<cv::Vec2i> pairs;  // (a, b) with a < b, superpixel ids
  cv::Mat1f features;            // pairs.size() x kNumOcclusionFeatures
  // Boundary pixels (label 0 with at least two labels in their 3x3 neighbourhood) and, in CSR
  // form, the pairs each one borders: pixel_pairs[pixel_offsets[i] .. pixel_offsets[i + 1]).
  std::vector<int> boundary_pixels;  // flat index y * width + x
  std::vector<int> pixel_offsets;    // boundary_pixels.size() + 1 entries
  std::vector<int> pixel_pairs;
};

// Enumerates the adjacent pairs via the boundary pixels (every two distinct labels in a boundary
// pixel's 3x3 neighbourhood form a pair) and computes their features. Sizes must agree (the
// caller validates); superpixels.labels must hold 0..count.
SuperpixelPairs ComputeSuperpixelPairs(const cv::Mat3b& image, const cv::Mat1f& enhanced_edge,
                                       const Superpixels& superpixels);

// 0.5·Σ (p − q)² / (p + q) over bins where p + q > 0; inputs are normalised histograms.
float ChiSquaredDistance(const float* p, const float* q, int bins);

}  // namespace tod
