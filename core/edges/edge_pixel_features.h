// Per-cell feature vector of the pixel edge classifier (ALGORITHM.md §3.4 step 1): the SED-style
// channels of edge_channels.h sampled at a fixed pattern of offsets around the cell, plus
// absolute differences of the colour on opposite sides of it. Offsets are in half-resolution
// cells, so radius 1 / 2 cells = 2 / 4 full-resolution pixels. Samples outside the image are
// clamped to the border.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/edges/edge_channels.h"

namespace tod {

// Bumped whenever the pattern below changes; stored in saved models.
inline constexpr int kPixelFeatureLayoutVersion = 1;

struct PixelFeatureTap {
  int channel = 0;
  int dx = 0;
  int dy = 0;
  // false: value = channel(p + d); true: value = |channel(p + d) - channel(p - d)|
  bool opposite_difference = false;
};

// The fixed pattern (49 taps): all 13 channels at the centre; full-resolution gradient magnitude
// on the rings of radius 1 and 2; half-resolution gradient magnitude on the ring of radius 2;
// L, u, v differences across the cell in 4 directions at radius 2.
const std::vector<PixelFeatureTap>& PixelFeaturePattern();
int NumPixelFeatures();

// Fills feature rows for every cell of one half-resolution row.
class PixelFeatureExtractor {
 public:
  explicit PixelFeatureExtractor(const EdgeChannels& channels);
  int num_features() const { return static_cast<int>(pattern_.size()); }
  // out: num_features() floats for cell (row, col).
  void Extract(int row, int col, float* out) const;
  // One feature row per cell of half-resolution row `row`: (*features) becomes cols() x
  // num_features(). Same values as Extract, without per-tap border clamping inside the row.
  void ExtractRow(int row, cv::Mat1f* features) const;

 private:
  const EdgeChannels& channels_;
  const std::vector<PixelFeatureTap>& pattern_;
  int max_offset_ = 0;  // largest |dx| of the pattern
};

}  // namespace tod
