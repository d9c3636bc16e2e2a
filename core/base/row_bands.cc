#include "core/base/row_bands.h"

#include <algorithm>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace tod {

void ForEachRowBand(int rows, const std::function<void(const cv::Range&)>& band) {
  if (rows <= 0) return;
  // One thread gains nothing from bands and would pay each band's set-up: the whole image at
  // once, which is also the reference the bands are held to.
  if (cv::getNumThreads() <= 1) {
    band(cv::Range(0, rows));
    return;
  }
  const int bands = (rows + kRowsPerBand - 1) / kRowsPerBand;
  cv::parallel_for_(cv::Range(0, bands), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      band(cv::Range(b * kRowsPerBand, std::min(rows, (b + 1) * kRowsPerBand)));
    }
  });
}

cv::Mat SepFilterInRowBands(const cv::Mat& src, const cv::Mat& kernel_x, const cv::Mat& kernel_y) {
  cv::Mat filtered(src.size(), src.type());
  ForEachRowBand(src.rows, [&](const cv::Range& rows) {
    cv::Mat band = filtered.rowRange(rows);
    cv::sepFilter2D(src.rowRange(rows), band, src.depth(), kernel_x, kernel_y, cv::Point(-1, -1),
                    0.0, cv::BORDER_REFLECT);
  });
  return filtered;
}

}  // namespace tod
