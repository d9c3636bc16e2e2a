// The 20 features of a proposal (ALGORITHM.md §5), computed on one region's occlusion edge map
// (un-normalised) and colour crop. Order is fixed:
//  0 max edge, 1 mode edge, 2 mode proportion, 3 inner mean edge, 4 inner edge density,
//  5 mean edge, 6 edge density, 7 normalised area, 8 aspect ratio, 9 objectness,
//  10 X centre, 11 Y centre, 12 width, 13 height (full-image coordinates / actual image size),
//  14-16 H/S/V standard deviation, 17-19 H/S/V contrast against the surround ring.
#pragma once

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "core/base/types.h"

namespace tod {

inline constexpr int kNumBoxFeatures = 20;
using BoxFeatureVector = std::array<float, kNumBoxFeatures>;

class BoxFeatureExtractor {
 public:
  // region_map: occlusion edge map of the region crop; region_bgr: colour crop of the same size;
  // region_origin: crop's top-left in the full image; image_size: full frame size.
  // Builds all integral images once, so each box costs O(1) except features 0-2.
  BoxFeatureExtractor(const cv::Mat1f& region_map, const cv::Mat3b& region_bgr,
                      cv::Point region_origin, cv::Size image_size);

  // box: full-image coordinates; clipped to the region first. objectness: the OLP score.
  BoxFeatureVector Compute(const Box& box, float objectness) const;

 private:
  cv::Mat1f map_;
  cv::Point origin_;
  cv::Size image_size_;
  cv::Mat1d map_sum_;        // integral of M
  cv::Mat1i map_count_;      // integral of M > 0
  std::array<cv::Mat1d, 3> hsv_sum_;
  std::array<cv::Mat1d, 3> hsv_sq_sum_;
  std::vector<cv::Mat1i> hist_integrals_;  // 48: 16 H bins, 16 S bins, 16 V bins
};

}  // namespace tod
