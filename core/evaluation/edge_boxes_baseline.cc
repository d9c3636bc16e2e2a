#include "core/evaluation/edge_boxes_baseline.h"

#include <cmath>
#include <opencv2/ximgproc/edgeboxes.hpp>

#include "core/proposals/edge_orientation.h"

namespace tod {

cv::Mat1f ThinEdges(const cv::Mat1f& edge, const cv::Mat1f& orientation) {
  cv::Mat1f out = cv::Mat1f::zeros(edge.size());
  for (int y = 0; y < edge.rows; ++y)
    for (int x = 0; x < edge.cols; ++x) {
      const float e = edge(y, x);
      if (e <= 0.f) continue;
      // The edge runs along theta, so its neighbours across the edge lie along the normal.
      const float nx = std::cos(orientation(y, x) + static_cast<float>(CV_PI / 2));
      const float ny = std::sin(orientation(y, x) + static_cast<float>(CV_PI / 2));
      const int dx = static_cast<int>(std::lround(nx)), dy = static_cast<int>(std::lround(ny));
      const auto at = [&](int xx, int yy) {
        return (xx < 0 || yy < 0 || xx >= edge.cols || yy >= edge.rows) ? 0.f : edge(yy, xx);
      };
      if (e >= at(x + dx, y + dy) && e >= at(x - dx, y - dy)) out(y, x) = e;
    }
  return out;
}

std::vector<Box> EdgeBoxesBaseline(const cv::Mat1f& base_edge, const Box& r1, int max_boxes) {
  if (base_edge.empty()) return {};
  const cv::Mat1f orientation = ComputeEdgeOrientation(base_edge);
  const cv::Mat1f thin = ThinEdges(base_edge, orientation);
  cv::Ptr<cv::ximgproc::EdgeBoxes> eb = cv::ximgproc::createEdgeBoxes(0.65f, 0.75f);
  eb->setMaxBoxes(max_boxes);
  std::vector<cv::Rect> rects;
  eb->getBoundingBoxes(thin, orientation, rects);
  std::vector<Box> out;
  out.reserve(rects.size());
  for (const cv::Rect& r : rects) out.push_back({r.x + r1.x, r.y + r1.y, r.width, r.height});
  return out;
}

}  // namespace tod
