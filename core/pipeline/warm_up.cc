#include "core/pipeline/warm_up.h"

#include <algorithm>
#include <chrono>
#include <opencv2/imgproc.hpp>

namespace tod {

cv::Mat3b WarmUpFrame(const WarmUpParams& params) {
  cv::Mat3b frame(std::max(params.height, 16), std::max(params.width, 16));
  // Sky-to-road brightness ramp with a little horizontal texture, so the edge and superpixel
  // stages see gradients everywhere and not a flat image.
  for (int y = 0; y < frame.rows; ++y) {
    for (int x = 0; x < frame.cols; ++x) {
      const int ramp = 200 - 120 * y / frame.rows;
      const int texture = ((x / 7 + y / 5) % 3) * 6;
      const auto v = static_cast<uchar>(std::clamp(ramp + texture, 0, 255));
      frame(y, x) = cv::Vec3b(v, static_cast<uchar>(v * 9 / 10), static_cast<uchar>(v * 8 / 10));
    }
  }
  // Dark blocks in the lower half, where the regions are: something for the proposal stage.
  for (int k = 0; k < 4; ++k) {
    const int w = frame.cols / (12 + 4 * k), h = frame.rows / (10 + 3 * k);
    const cv::Point corner(frame.cols * (1 + 2 * k) / 9, frame.rows * (5 + k) / 10);
    cv::rectangle(frame, cv::Rect(corner, cv::Size(w, h)), cv::Scalar(30 + 10 * k, 35, 40),
                  cv::FILLED);
  }
  return frame;
}

Result<double> WarmUp(const Detector& detector, const WarmUpParams& params) {
  DetectOptions options;
  options.budget_ms = 0;  // the warm-up must run every stage whatever the machine's speed
  options.max_proposals = 1;
  options.want_probability_map = true;  // the map stage runs as for a served request
  const cv::Mat3b frame = WarmUpFrame(params);
  const auto start = std::chrono::steady_clock::now();
  Result<Detection> detection = detector.Detect(frame, options);
  if (!detection.ok()) return detection.status().WithContext("warm-up detection");
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace tod
