#include "client/overlay.h"

#include "core/pipeline/detection_output.h"

namespace tod::client {
namespace {

Box FromProto(const tod::v1::Box& box) { return {box.x(), box.y(), box.w(), box.h()}; }

}  // namespace

cv::Mat3b DrawOverlay(const cv::Mat3b& image, const tod::v1::DetectResponse& response,
                      const cv::Mat1b& probability, const OverlayStyle& style) {
  Detection detection;
  detection.width = image.cols;
  detection.height = image.rows;
  for (const tod::v1::Proposal& p : response.proposals())
    detection.proposals.push_back({FromProto(p.box()), p.fused(), p.ordr(), p.obdr()});
  for (const tod::v1::Obstacle& o : response.obstacles())
    detection.obstacles.push_back({FromProto(o.box()), o.area(), o.peak_probability(),
                                   o.mean_probability(), o.evidence(), o.score()});
  if (!probability.empty() && probability.size() == image.size())
    probability.convertTo(detection.probability, CV_32F, 1.0 / 255.0);
  return tod::DrawOverlay(image, detection, style.proposals_drawn);
}

}  // namespace tod::client
