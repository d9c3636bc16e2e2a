#include "core/edges/edge_pixel_features.h"

#include <algorithm>
#include <cmath>

namespace tod {
namespace {

std::vector<PixelFeatureTap> BuildPattern() {
  std::vector<PixelFeatureTap> pattern;
  for (int c = 0; c < kNumEdgeChannels; ++c) pattern.push_back({c, 0, 0, false});
  // Ring of 8 positions at Chebyshev radius r: the 4 axis and the 4 diagonal neighbours.
  const auto add_ring = [&pattern](int channel, int r) {
    for (int dy = -r; dy <= r; dy += r) {
      for (int dx = -r; dx <= r; dx += r) {
        if (dx != 0 || dy != 0) pattern.push_back({channel, dx, dy, false});
      }
    }
  };
  add_ring(kChanGradFull, 1);
  add_ring(kChanGradFull, 2);
  add_ring(kChanGradHalf, 2);
  // Colour contrast across the cell: a boundary through the cell separates p + d from p - d.
  const int directions[4][2] = {{2, 0}, {0, 2}, {2, 2}, {2, -2}};
  for (const auto& d : directions) {
    for (int c = kChanL; c <= kChanV; ++c) pattern.push_back({c, d[0], d[1], true});
  }
  return pattern;
}

}  // namespace

const std::vector<PixelFeatureTap>& PixelFeaturePattern() {
  static const std::vector<PixelFeatureTap> pattern = BuildPattern();
  return pattern;
}

int NumPixelFeatures() { return static_cast<int>(PixelFeaturePattern().size()); }

PixelFeatureExtractor::PixelFeatureExtractor(const EdgeChannels& channels)
    : channels_(channels), pattern_(PixelFeaturePattern()) {
  for (const PixelFeatureTap& tap : pattern_) max_offset_ = std::max(max_offset_, std::abs(tap.dx));
}

void PixelFeatureExtractor::Extract(int row, int col, float* out) const {
  const int last_row = channels_.rows() - 1;
  const int last_col = channels_.cols() - 1;
  const auto at = [&](int channel, int y, int x) {
    return channels_.planes[channel](std::clamp(y, 0, last_row), std::clamp(x, 0, last_col));
  };
  for (const PixelFeatureTap& tap : pattern_) {
    const float forward = at(tap.channel, row + tap.dy, col + tap.dx);
    *out++ = tap.opposite_difference
                 ? std::abs(forward - at(tap.channel, row - tap.dy, col - tap.dx))
                 : forward;
  }
}

void PixelFeatureExtractor::ExtractRow(int row, cv::Mat1f* features) const {
  const int cols = channels_.cols();
  const int last_row = channels_.rows() - 1;
  features->create(cols, num_features());
  // Row pointers of every tap (forward p + d, backward p - d), clamped once per row.
  std::vector<const float*> forward(pattern_.size());
  std::vector<const float*> backward(pattern_.size());
  for (std::size_t k = 0; k < pattern_.size(); ++k) {
    const PixelFeatureTap& tap = pattern_[k];
    const cv::Mat1f& plane = channels_.planes[tap.channel];
    forward[k] = plane.ptr<float>(std::clamp(row + tap.dy, 0, last_row));
    backward[k] = plane.ptr<float>(std::clamp(row - tap.dy, 0, last_row));
  }
  const int interior_begin = std::min(max_offset_, cols);
  const int interior_end = std::max(cols - max_offset_, interior_begin);
  for (int col = 0; col < cols; ++col) {
    float* out = features->ptr<float>(col);
    if (col >= interior_begin && col < interior_end) {
      for (std::size_t k = 0; k < pattern_.size(); ++k) {
        const PixelFeatureTap& tap = pattern_[k];
        const float value = forward[k][col + tap.dx];
        out[k] = tap.opposite_difference ? std::abs(value - backward[k][col - tap.dx]) : value;
      }
    } else {
      Extract(row, col, out);
    }
  }
}

}  // namespace tod
