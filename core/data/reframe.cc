#include "core/data/reframe.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

cv::Mat Scaled(const cv::Mat& image, double scale, ReframeKind kind) {
  if (scale == 1.0) return image.clone();
  const cv::Size size(static_cast<int>(std::lround(image.cols * scale)),
                      static_cast<int>(std::lround(image.rows * scale)));
  const int interpolation = kind == ReframeKind::kLabels ? cv::INTER_NEAREST
                            : scale < 1.0                ? cv::INTER_AREA
                                                         : cv::INTER_LINEAR;
  cv::Mat out;
  cv::resize(image, out, size, 0, 0, interpolation);
  return out;
}

cv::Mat CentreCropped(const cv::Mat& image, cv::Size crop) {
  const int w = crop.width > 0 ? crop.width : image.cols;
  const int h = crop.height > 0 ? crop.height : image.rows;
  if (w > image.cols || h > image.rows) return {};
  return image(cv::Rect((image.cols - w) / 2, (image.rows - h) / 2, w, h)).clone();
}

cv::Mat Shifted(const cv::Mat& image, double shift_up, ReframeKind kind, int void_label) {
  const int rows = static_cast<int>(std::lround(shift_up * image.rows));
  if (rows == 0 || std::abs(rows) >= image.rows) return image;
  const int top = rows < 0 ? -rows : 0;
  const int bottom = rows > 0 ? rows : 0;
  const cv::Mat kept = image.rowRange(bottom, image.rows - top);
  cv::Mat out;
  if (kind == ReframeKind::kLabels) {
    cv::copyMakeBorder(kept, out, top, bottom, 0, 0, cv::BORDER_CONSTANT, cv::Scalar(void_label));
  } else {
    cv::copyMakeBorder(kept, out, top, bottom, 0, 0, cv::BORDER_REPLICATE);
  }
  return out;
}

}  // namespace

cv::Mat Reframe(const cv::Mat& image, const ReframeParams& params, ReframeKind kind,
                int void_label) {
  const cv::Mat cropped = CentreCropped(Scaled(image, params.scale, kind), params.crop);
  if (cropped.empty()) return {};
  return Shifted(cropped, params.shift_up, kind, void_label);
}

}  // namespace tod
