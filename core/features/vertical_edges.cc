#include "core/features/vertical_edges.h"

#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

constexpr std::uint8_t kNoBin = 255;

// The orientation bin of a counted pixel's gradient (see the header): its direction modulo 180°,
// bins of 180° / 8 centred on multiples of 22.5°.
std::uint8_t OrientationBin(float dx, float dy) {
  double angle = std::atan2(static_cast<double>(dy), static_cast<double>(dx));
  if (angle < 0.0) angle += CV_PI;
  const int bin = static_cast<int>(std::floor(angle / CV_PI * kGradientOrientationBins + 0.5));
  return static_cast<std::uint8_t>(bin % kGradientOrientationBins);
}

// Integral counts per bin of a bin map (kNoBin: not counted), the bins of a cell side by side.
// Rows are summed on OpenCV's pool, then the columns in slices: the same table for any thread
// count (integer sums).
std::vector<std::uint32_t> OrientationIntegrals(const cv::Mat1b& bins) {
  const int rows = bins.rows, cols = bins.cols;
  const std::size_t stride = static_cast<std::size_t>(cols + 1) * kGradientOrientationBins;
  std::vector<std::uint32_t> table(static_cast<std::size_t>(rows + 1) * stride, 0u);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) {
      std::uint32_t* out = table.data() + static_cast<std::size_t>(y + 1) * stride;
      std::array<std::uint32_t, kGradientOrientationBins> run{};
      const std::uint8_t* in = bins[y];
      for (int x = 0; x < cols; ++x) {
        if (in[x] != kNoBin) ++run[in[x]];
        std::copy(run.begin(), run.end(),
                  out + static_cast<std::size_t>(x + 1) * kGradientOrientationBins);
      }
    }
  });
  constexpr int kSlice = 4096;
  const int slices = static_cast<int>((stride + kSlice - 1) / kSlice);
  cv::parallel_for_(cv::Range(0, slices), [&](const cv::Range& range) {
    for (int s = range.start; s < range.end; ++s) {
      const std::size_t begin = static_cast<std::size_t>(s) * kSlice;
      const std::size_t end = std::min(stride, begin + kSlice);
      for (int y = 2; y <= rows; ++y) {
        std::uint32_t* row = table.data() + static_cast<std::size_t>(y) * stride;
        const std::uint32_t* above = row - stride;
        for (std::size_t i = begin; i < end; ++i) row[i] += above[i];
      }
    }
  });
  return table;
}

}  // namespace

VerticalEdgeIntegrals::VerticalEdgeIntegrals(const cv::Mat3b& bgr, cv::Point crop_origin,
                                             const VerticalEdgeParams& params)
    : size_(bgr.size()), origin_(crop_origin) {
  // The grey crop is a matrix of its own, so the derivatives reflect at the crop's border instead
  // of reading the frame around it: a crop gives the same table wherever it was cut from.
  cv::Mat1b grey8;
  cv::cvtColor(bgr, grey8, cv::COLOR_BGR2GRAY);
  cv::Mat1f grey, gx, gy;
  grey8.convertTo(grey, CV_32F);
  cv::Sobel(grey, gx, CV_32F, 1, 0, 3);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 3);
  cv::Mat1f vertical(grey.size()), counted(grey.size());
  cv::Mat1b bins;
  if (params.orientation_tables) bins.create(grey.size());
  const double max_sine = std::sin(params.max_tilt_degrees * CV_PI / 180.0);
  cv::parallel_for_(cv::Range(0, grey.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const float* dx = gx[y];
      const float* dy = gy[y];
      float* v = vertical[y];
      float* c = counted[y];
      for (int x = 0; x < grey.cols; ++x) {
        const float magnitude = std::hypot(dx[x], dy[x]);
        const bool counts = magnitude >= params.min_gradient;
        c[x] = counts ? magnitude : 0.f;
        // The edge runs perpendicular to the gradient: vertical when the gradient is horizontal.
        v[x] =
            counts && std::abs(dy[x]) / static_cast<double>(magnitude) < max_sine ? magnitude : 0.f;
        if (!bins.empty()) bins(y, x) = counts ? OrientationBin(dx[x], dy[x]) : kNoBin;
      }
    }
  });
  cv::integral(vertical, vertical_sum_, CV_64F);
  cv::integral(counted, counted_sum_, CV_64F);
  if (!bins.empty()) orientation_sum_ = OrientationIntegrals(bins);
}

double VerticalEdgeIntegrals::Share(const cv::Rect& rect) const {
  const auto sum = [&rect](const cv::Mat1d& table) {
    const int x0 = rect.x, y0 = rect.y, x1 = rect.x + rect.width, y1 = rect.y + rect.height;
    return table(y1, x1) - table(y0, x1) - table(y1, x0) + table(y0, x0);
  };
  const double counted = sum(counted_sum_);
  return counted > 0.0 ? sum(vertical_sum_) / counted : 0.0;
}

double VerticalEdgeIntegrals::OrientationEntropy(const cv::Rect& rect) const {
  if (orientation_sum_.empty()) return 0.0;
  const std::size_t stride = static_cast<std::size_t>(size_.width + 1) * kGradientOrientationBins;
  const auto cell = [&](int y, int x) {
    return orientation_sum_.data() + static_cast<std::size_t>(y) * stride +
           static_cast<std::size_t>(x) * kGradientOrientationBins;
  };
  const std::uint32_t* a = cell(rect.y, rect.x);
  const std::uint32_t* b = cell(rect.y, rect.x + rect.width);
  const std::uint32_t* c = cell(rect.y + rect.height, rect.x);
  const std::uint32_t* d = cell(rect.y + rect.height, rect.x + rect.width);
  std::array<std::uint32_t, kGradientOrientationBins> counts{};
  std::uint64_t total = 0;
  for (int k = 0; k < kGradientOrientationBins; ++k) {
    counts[k] = d[k] - b[k] - c[k] + a[k];  // exact: unsigned arithmetic wraps back
    total += counts[k];
  }
  if (total == 0) return 0.0;
  double entropy = 0.0;
  for (const std::uint32_t n : counts) {
    if (n == 0) continue;
    const double q = static_cast<double>(n) / static_cast<double>(total);
    entropy -= q * std::log(q);
  }
  return entropy / std::log(static_cast<double>(kGradientOrientationBins));
}

}  // namespace tod
