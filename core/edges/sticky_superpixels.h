// Sticky-edge superpixels (ALGORITHM.md §3.2(1)): a k-means-like label refinement where the cost
// rewards placing boundaries on strong (enhanced) edges. Our own implementation.
#pragma once

#include <opencv2/core.hpp>

#include "core/base/status.h"

namespace tod {

struct StickySuperpixelParams {
  int k = 1024;        // scale: larger k -> larger superpixels
  float alpha = 0.5f;  // regularity vs data
  float beta = 0.9f;   // edge vs colour
  int iterations = 4;  // full-resolution iterations (2x at half resolution)
};

struct Superpixels {
  cv::Mat1i labels;  // 0 = 1-pixel boundary between superpixels, 1..count = superpixel id
  int count = 0;
};

// bgr: crop; edge: enhanced edge map Ê of the same size (values may exceed 1). Invalid input (see
// ValidateSuperpixelInput) is an error that names the reason.
Result<Superpixels> ComputeStickySuperpixels(const cv::Mat3b& bgr, const cv::Mat1f& edge,
                                             const StickySuperpixelParams& params = {});

// The colour the refinement compares: `colour` smoothed by the radius-1 triangle filter [1 2 1]/4
// in both directions (borders reflected), computed in bands of rows on OpenCV's pool; the same
// pixels as one cv::sepFilter2D call over the whole image (its reference; the test compares them).
cv::Mat3f SmoothStickyColour(const cv::Mat3f& colour);

// Non-empty image, edge map of the same size and finite, k > 0, alpha and beta in [0,1],
// iterations >= 0.
Status ValidateSuperpixelInput(const cv::Mat3b& bgr, const cv::Mat1f& edge,
                               const StickySuperpixelParams& params);

}  // namespace tod
