// OLP box scoring on an occlusion edge map (ALGORITHM.md §4.1-4.2): Edge Boxes without adaptive
// NMS - edge groups, group affinities, box score with the inner-box subtraction and boundary-
// crossing removal, the sliding-window grid with a per-region stride factor (the multistride
// change, §4.2.6), refinement and NMS. Our own implementation.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "core/base/types.h"

namespace tod {

struct EdgeBoxParams {
  float alpha = 0.65f;           // step / IoU between neighbouring windows
  float beta = 0.75f;            // NMS IoU
  float min_score = 0.01f;
  int max_boxes = 10000;         // after NMS
  float edge_min_mag = 0.1f;
  float edge_merge_thr = 0.5f;
  float cluster_min_mag = 0.5f;
  float max_aspect_ratio = 6.f;  // tau_a
  float min_box_area = 100.f;    // paper: windows "from 100 pixels" (code: 60)
  float gamma = 2.f;             // affinity exponent
  float kappa = 1.5f;            // size normalisation exponent
  float stride_factor = 1.f;     // MS: (K - k + 1) / K for region k; 1 = plain sliding window
  int min_stride = 2;            // px
  bool refine = true;
};

// edge_map: the region's occlusion-edge map normalised to max 1 (call NormaliseToMax first).
// Returns region-relative boxes sorted by score, descending, after NMS.
std::vector<ScoredBox> ScoreEdgeBoxes(const cv::Mat1f& edge_map, const EdgeBoxParams& params);

// Scores one given box on the map (the same score the sliding window gives, no refinement).
float ScoreSingleBox(const cv::Mat1f& edge_map, const Box& box, const EdgeBoxParams& params);

// M / max(M) (unchanged when max is 0).
cv::Mat1f NormaliseToMax(const cv::Mat1f& map);

// §3.2(4): zero boundary pixels on the outermost rows / columns of a region crop that merely run
// along the crop border (prevents artificial frame edges). Applied for regions k >= 2.
void ClearCropBorderEdges(cv::Mat1f& region_map);

// Greedy NMS: keeps a box if its IoU with every kept box is <= iou_threshold; input any order,
// output sorted by score descending, at most max_boxes.
std::vector<ScoredBox> NonMaximumSuppression(std::vector<ScoredBox> boxes, float iou_threshold,
                                             int max_boxes);

}  // namespace tod
