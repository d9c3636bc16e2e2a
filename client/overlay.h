// A picture of a detection received over the wire, drawn exactly as `tod detect` draws its own
// overlay (core/pipeline/detection_output.h): the response is turned back into a Detection.
#pragma once

#include <opencv2/core.hpp>

#include "tod/v1/obstacle_discovery.pb.h"

namespace tod::client {

struct OverlayStyle {
  int proposals_drawn = 10;  // best-first proposals outlined
};

// `probability` (8-bit, 255 = 1.0) may be empty (map not requested) or must match the image size.
cv::Mat3b DrawOverlay(const cv::Mat3b& image, const tod::v1::DetectResponse& response,
                      const cv::Mat1b& probability, const OverlayStyle& style = {});

}  // namespace tod::client
