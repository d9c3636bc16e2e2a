// A picture of a detection for people: the probability map tinted red over the frame, obstacle
// boxes in red, the best proposals in thin green.
#pragma once

#include <opencv2/core.hpp>

#include "tod/v1/obstacle_discovery.pb.h"

namespace tod::client {

struct OverlayStyle {
  int proposals_drawn = 10;  // best-first proposals outlined
  double map_opacity = 0.5;  // red tint at P = 1
};

// `probability` may be empty (map not requested) or must match the image size.
cv::Mat3b DrawOverlay(const cv::Mat3b& image, const tod::v1::DetectResponse& response,
                      const cv::Mat1b& probability, const OverlayStyle& style = {});

}  // namespace tod::client
