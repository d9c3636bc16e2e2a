// The edge features 1-7 of ALGORITHM.md §5 from a sparse copy of a region's occlusion edge map.
//
// M is zero almost everywhere (a few % of the pixels lie on superpixel boundaries), so instead of
// dense integral images (12 B/pixel) it keeps only the non-zero pixels (12 B each). They are
// stored band-major: the map is cut into vertical bands 64 columns wide and each band holds its
// entries row by row, so the rows of a box are one sequential stream per band instead of one
// cache miss per row. One pass over the box then yields max, mode and mode share (features 1-3)
// and the sums and counts of the box and of its centre sub-box (features 4-7): O(box height x
// bands + edge pixels in the box).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"

namespace tod {

// Edge statistics of one box and its centre sub-box.
struct BoxEdgeStats {
  float max_value = 0.f;   // largest value > 0 (0 if none)
  float mode_value = 0.f;  // most frequent value > 0, smallest on ties (0 if none)
  int mode_count = 0;      // pixels holding mode_value
  int count = 0;           // pixels with M > 0 in the box
  double sum = 0.0;        // sum of M over the box
  int inner_count = 0;     // pixels with M > 0 in the centre sub-box
  double inner_sum = 0.0;  // sum of M over the centre sub-box
};

class SparseEdgeMap {
 public:
  SparseEdgeMap() = default;
  // Fails (naming region_map) if the map holds NaN or infinity.
  static Result<SparseEdgeMap> Build(const cv::Mat1f& region_map);

  cv::Size size() const { return size_; }
  // box: region-local, inside the map; inner: inside box (may be empty). Thread-safe.
  BoxEdgeStats Measure(const cv::Rect& box, const cv::Rect& inner) const;

 private:
  static constexpr int kBandShift = 6;  // bands of 64 columns
  static constexpr int kBandWidth = 1 << kBandShift;

  struct Entry {
    int column;   // full-region column
    float value;  // M (non-zero, may be negative)
    int id;       // index into distinct_values_, -1 if M < 0
  };

  cv::Size size_;
  int bands_ = 0;
  // bands_ x (rows + 1): entries of band b, row y are [row_start_[b (rows + 1) + y], ... + y + 1).
  std::vector<int> row_start_;
  std::vector<Entry> entries_;          // band-major, then row, then column
  std::vector<float> distinct_values_;  // distinct positive values, in order of appearance
};

}  // namespace tod
