#include "client/overlay.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace tod::client {
namespace {

cv::Rect ToRect(const tod::v1::Box& box) { return {box.x(), box.y(), box.w(), box.h()}; }

}  // namespace

cv::Mat3b DrawOverlay(const cv::Mat3b& image, const tod::v1::DetectResponse& response,
                      const cv::Mat1b& probability, const OverlayStyle& style) {
  cv::Mat3b overlay = image.clone();
  if (!probability.empty() && probability.size() == image.size()) {
    for (int y = 0; y < overlay.rows; ++y) {
      for (int x = 0; x < overlay.cols; ++x) {
        const double alpha = style.map_opacity * probability(y, x) / 255.0;
        cv::Vec3b& pixel = overlay(y, x);
        pixel[0] = cv::saturate_cast<uchar>((1 - alpha) * pixel[0]);
        pixel[1] = cv::saturate_cast<uchar>((1 - alpha) * pixel[1]);
        pixel[2] = cv::saturate_cast<uchar>((1 - alpha) * pixel[2] + alpha * 255);
      }
    }
  }
  const int proposals = std::min(style.proposals_drawn, response.proposals_size());
  for (int i = 0; i < proposals; ++i) {
    cv::rectangle(overlay, ToRect(response.proposals(i).box()), cv::Scalar(0, 200, 0), 1);
  }
  for (const tod::v1::Obstacle& obstacle : response.obstacles()) {
    cv::rectangle(overlay, ToRect(obstacle.box()), cv::Scalar(0, 0, 255), 2);
  }
  return overlay;
}

}  // namespace tod::client
