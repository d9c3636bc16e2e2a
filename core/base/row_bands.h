// Whole-image pixel work split into bands of rows on OpenCV's pool (as wide as the request's
// threads). Each helper gives exactly the pixels of one call over the whole image, so one thread
// and several give the same values; the whole-image call stays the reference the tests hold
// them to.
#pragma once

#include <functional>
#include <opencv2/core.hpp>

namespace tod {

// Rows per band: a band's set-up (a filter's ring buffer, a conversion's tables) is paid once per
// band, and a 1024-row frame still gives 16 bands to balance two to four threads.
inline constexpr int kRowsPerBand = 64;

// Runs band(rows) for consecutive ranges of at most kRowsPerBand rows covering [0, rows), on
// OpenCV's pool; with one thread (cv::getNumThreads() == 1), once over all rows. Bands must write
// only their own rows.
void ForEachRowBand(int rows, const std::function<void(const cv::Range&)>& band);

// cv::sepFilter2D(src, dst, src.depth(), kernel_x, kernel_y, anchor centred, delta 0,
// BORDER_REFLECT) over the whole image, computed band by band. A band is a view into src, and
// OpenCV's filters read the rows beyond a view from its parent (the border rule applies at the
// image's own edges only), so every band's pixels are those of the whole-image call.
cv::Mat SepFilterInRowBands(const cv::Mat& src, const cv::Mat& kernel_x, const cv::Mat& kernel_y);

}  // namespace tod
