// The baseline a user would otherwise pick (issue 3, variant "EB"): OpenCV ximgproc Edge Boxes on
// the same base edge map over R1 (alpha 0.65, beta 0.75, 1000 boxes, OpenCV's other defaults).
// Edge Boxes expects thin edges (its authors run edge NMS first), so the map is thinned by
// non-maximum suppression across the edge orientation before scoring.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/base/types.h"

namespace tod {

// Keeps a pixel only where it is at least as strong as both neighbours across its edge
// (orientation theta in [0, pi) as ComputeEdgeOrientation returns); others become 0.
cv::Mat1f ThinEdges(const cv::Mat1f& edge, const cv::Mat1f& orientation);

// Boxes in full-image coordinates (the map covers `r1`), best first, at most max_boxes.
std::vector<Box> EdgeBoxesBaseline(const cv::Mat1f& base_edge, const Box& r1, int max_boxes = 1000);

}  // namespace tod
