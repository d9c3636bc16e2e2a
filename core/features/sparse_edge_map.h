// The edge features 1-7 of ALGORITHM.md §5 from a sparse copy of a region's occlusion edge map.
//
// M is zero almost everywhere (10-20 % of the pixels lie on superpixel boundaries) and constant
// along each boundary segment, so a row of M is a short list of runs (maximal stretches of one
// non-zero value; about two pixels each on superpixel boundaries). Each run names its value by a
// dense id. Per box, one pass over the runs that meet the box's rows adds each run's clipped
// length to a per-id count; max, mode and mode share (features 1-3) then come from the few ids
// touched, and so do the sum and count of the box (features 6-7). The centre sub-box (features
// 4-5) is measured in the same pass. A row index (the first run of every 16-column block) starts
// each row at the box's left edge. Cost: O(box height + runs in the box + distinct values).
//
// Exactness of the sums: the original summed the float values one pixel at a time into a double,
// band by band (64 columns), row by row. When every value is an integer multiple of a power of
// two q (the ulp of the smallest |value|) and the total sum of |M| over the map is at most
// 2^53 q, every partial sum is a multiple of q of at most 53 bits, so no addition ever rounded
// and the result is the exact sum, whatever the order. Build checks this (it holds with a wide
// margin for occlusion maps: values in [0.01, 1], ~43 of the 53 bits used); then sums are exact
// int64 counts of q, computed per id. Otherwise Measure repeats the original pixel order.
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
  static constexpr int kIndexShift = 4;  // row index: one entry per 16 columns
  // Band width of the original summation order (used only when the sums are not provably exact).
  static constexpr int kBandShift = 6;

  struct Run {
    int begin;  // first column
    int end;    // one past the last column
    int id;     // index into values_
  };

  // Sets units_, quantum_ and sums_exact_: whether every box sum can be taken exactly in integer
  // units of the smallest ulp among values_ (pixels_of_id[id]: the map's pixels of value id).
  void DecideExactSums(const std::vector<std::int64_t>& pixels_of_id);
  // Pixels of one value id in a box and in its centre sub-box (Measure's scratch).
  struct Tally {
    int box;
    int inner;
  };

  // First run of row y that ends after column x (x inside the map).
  int FirstRunAfter(int y, int x) const;
  // Measure's first step: adds every run's pixels in `box` and `inner` to tally[id] and lists
  // each id seen for the first time in touched_ids; returns how many it listed.
  int TallyRuns(const cv::Rect& box, const cv::Rect& inner, Tally* tally, int* touched_ids) const;
  // Measure's second step: features 1-7 from the listed ids' tallies, which it resets to zero.
  BoxEdgeStats StatsFromTallies(const cv::Rect& box, const cv::Rect& inner, Tally* tally,
                                const int* touched_ids, int num_touched) const;
  // The original (band-major, pixel by pixel) double sums; the fallback when !sums_exact_.
  void SequentialSums(const cv::Rect& box, const cv::Rect& inner, BoxEdgeStats& stats) const;

  cv::Size size_;
  int index_stride_ = 0;        // index entries per row: (cols >> kIndexShift) + 1
  std::vector<int> row_start_;  // rows + 1: runs of row y are [row_start_[y], row_start_[y + 1])
  std::vector<int> first_run_;  // rows x index_stride_: FirstRunAfter(y, c << kIndexShift)
  std::vector<Run> runs_;       // row-major, columns ascending
  std::vector<float> values_;   // distinct non-zero values, in order of appearance
  std::vector<std::int64_t> units_;  // values_[id] / quantum_ (exact) when sums_exact_
  bool sums_exact_ = false;
  double quantum_ = 0.0;  // q, a power of two
};

}  // namespace tod
