#include "core/calibration/camera_horizon.h"

#include <algorithm>

namespace tod {

void CameraHorizon::Add(double row) {
  rows_[static_cast<std::size_t>(frames_ % static_cast<long long>(kWindow))] = row;
  ++frames_;
}

std::optional<double> CameraHorizon::Estimate() const {
  if (frames_ == 0) return std::nullopt;
  const std::size_t n = std::min<std::size_t>(kWindow, static_cast<std::size_t>(frames_));
  std::array<double, kWindow> sorted = rows_;
  std::sort(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n));
  return n % 2 == 1 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

}  // namespace tod
