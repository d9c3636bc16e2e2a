#include "core/features/vertical_edges.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tod {
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
      }
    }
  });
  cv::integral(vertical, vertical_sum_, CV_64F);
  cv::integral(counted, counted_sum_, CV_64F);
}

double VerticalEdgeIntegrals::Share(const cv::Rect& rect) const {
  const auto sum = [&rect](const cv::Mat1d& table) {
    const int x0 = rect.x, y0 = rect.y, x1 = rect.x + rect.width, y1 = rect.y + rect.height;
    return table(y1, x1) - table(y0, x1) - table(y1, x0) + table(y0, x0);
  };
  const double counted = sum(counted_sum_);
  return counted > 0.0 ? sum(vertical_sum_) / counted : 0.0;
}

}  // namespace tod
