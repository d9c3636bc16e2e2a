// A camera's horizon from the frames it has sent: the median of its last frames' estimates, so a
// frame the estimator gets wrong (a truck's flank, a turn) does not move it. Fixed memory.
#pragma once

#include <array>
#include <cstddef>
#include <optional>

namespace tod {

class CameraHorizon {
 public:
  static constexpr std::size_t kWindow = 64;  // the frames the median is taken over

  // One frame's estimate (full-frame row).
  void Add(double row);
  // The median of the last kWindow estimates; none before the first.
  std::optional<double> Estimate() const;
  // Estimates added over the camera's life (the median uses the last kWindow of them).
  long long frames() const { return frames_; }

 private:
  std::array<double, kWindow> rows_{};
  long long frames_ = 0;
};

}  // namespace tod
