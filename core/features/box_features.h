// The 20 features of a proposal (ALGORITHM.md §5), computed on one region's occlusion edge map
// (un-normalised) and colour crop. Order is fixed:
//  0 max edge, 1 mode edge, 2 mode proportion, 3 inner mean edge, 4 inner edge density,
//  5 mean edge, 6 edge density, 7 normalised area, 8 aspect ratio, 9 objectness,
//  10 X centre, 11 Y centre, 12 width, 13 height (full-image coordinates / actual image size),
//  14-16 H/S/V standard deviation, 17-19 H/S/V contrast against the surround ring.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

inline constexpr int kNumBoxFeatures = 20;
using BoxFeatureVector = std::array<float, kNumBoxFeatures>;

// Histogram layout of the colour-contrast features (ALGORITHM.md §5, features 18-20).
inline constexpr int kHueBins = 16;     // 17 non-uniform edges, last bin merged into the first
inline constexpr int kSatValBins = 16;  // uniform, width 1/16; 1.0 falls in the last bin
inline constexpr int kColourHistBins = kHueBins + 2 * kSatValBins;  // 48: H, then S, then V

struct BoxFeatureOptions {
  // ALGORITHM.md §5 "coordinates quirk": the original code computed features 10-11 from
  // region-relative box coordinates. Off by default (full-image coordinates, [R]); the flag
  // exists to reproduce models trained the old way. Features 12-13 do not depend on it.
  bool region_relative_centre = false;
};

// MATLAB rgb2hsv of one 8-bit BGR pixel: H, S, V all in [0, 1], H linear (not circular).
cv::Vec3f BgrToHsv(const cv::Vec3b& bgr);
// Hue histogram bin (0..15) of a hue given in degrees [0, 360).
int HueBin(double hue_degrees);
// Saturation / value histogram bin (0..15) of a value in [0, 1].
int SatValBin(float value);

class BoxFeatureExtractor {
 public:
  // region_map: occlusion edge map of the region crop; region_bgr: colour crop of the same size;
  // region_origin: crop's top-left in the full image; image_size: full frame size.
  // Builds all integral images once, so each box costs O(1) except features 0-2.
  // On invalid input (sizes differ, crop outside the frame, non-finite map values) the extractor
  // is empty, status() says why, and Compute() returns zeros except the objectness.
  BoxFeatureExtractor(const cv::Mat1f& region_map, const cv::Mat3b& region_bgr,
                      cv::Point region_origin, cv::Size image_size,
                      const BoxFeatureOptions& options = {});

  // Same as the constructor, but invalid input is an error instead of an empty extractor.
  static Result<BoxFeatureExtractor> Create(const cv::Mat1f& region_map,
                                            const cv::Mat3b& region_bgr, cv::Point region_origin,
                                            cv::Size image_size,
                                            const BoxFeatureOptions& options = {});

  const Status& status() const { return status_; }

  // box: full-image coordinates; clipped to the region first. objectness: the OLP score.
  BoxFeatureVector Compute(const Box& box, float objectness) const;

  // One row of 20 features per proposal (box + OLP score), in input order; thread-safe.
  cv::Mat1f ComputeAll(const std::vector<ScoredBox>& proposals) const;

 private:
  // Sums of the 48 histogram integrals over a region-local box.
  std::array<int, kColourHistBins> HistogramOf(const cv::Rect& local) const;

  Status status_;
  BoxFeatureOptions options_;
  // Features 1-3 visit only the edge pixels of a box: the non-zero pixels of M row by row
  // (compressed sparse rows), each stored as the rank of its value among the distinct non-zero
  // values, so the mode is a counting pass instead of a sort. Replaces the former dense
  // `cv::Mat1f map_` copy (the map itself is not needed after construction).
  cv::Size region_size_;
  std::vector<int> edge_row_start_;  // rows + 1 offsets into the two arrays below
  std::vector<int> edge_cols_;       // column of each edge pixel, ascending within a row
  std::vector<int> edge_ranks_;      // index into edge_values_
  std::vector<float> edge_values_;   // distinct non-zero values of M, ascending
  cv::Point origin_;
  cv::Size image_size_;
  cv::Mat1d map_sum_;    // integral of M
  cv::Mat1i map_count_;  // integral of M > 0
  std::array<cv::Mat1d, 3> hsv_sum_;
  std::array<cv::Mat1d, 3> hsv_sq_sum_;
  // 48 histogram integrals (16 H bins, 16 S bins, 16 V bins), stored interleaved: entry
  // ((y * (cols + 1)) + x) * 48 + bin. One box corner then reads 48 adjacent ints instead of
  // touching 48 separate images (the former std::vector<cv::Mat1i>; same content). Allocated
  // without zero-filling: every entry is written exactly once by the constructor.
  std::unique_ptr<std::int32_t[]> hist_integrals_;
};

}  // namespace tod
