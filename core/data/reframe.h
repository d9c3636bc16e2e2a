// A frame and its labels as another camera would have taken them (issue 48): scaled, cropped to
// another size or aspect ratio, and shifted up or down (a camera mounted lower or pitched up sees
// the horizon higher). Develops and measures self-calibration on labelled frames of one camera.
#pragma once

#include <opencv2/core.hpp>

namespace tod {

struct ReframeParams {
  double scale = 1.0;  // resize factor, applied first (area resampling down, linear up)
  // Centre crop to this size after scaling; 0 keeps that dimension. Larger than the scaled frame
  // is an error.
  cv::Size crop{0, 0};
  // The picture moves up by this share of the (cropped) height; negative moves it down. The rows
  // it uncovers repeat the edge row in the image and are void in the labels.
  double shift_up = 0.0;
};

// What is being reframed: a colour image (resampled), or a label image (nearest neighbour, the
// uncovered rows set to `void_label`).
enum class ReframeKind { kImage, kLabels };

// The reframed image, or an empty Mat when params ask for a crop larger than the scaled frame.
cv::Mat Reframe(const cv::Mat& image, const ReframeParams& params, ReframeKind kind,
                int void_label = 255);

}  // namespace tod
