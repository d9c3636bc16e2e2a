// OLP box scoring on an occlusion edge map (ALGORITHM.md §4.1-4.2): Edge Boxes without adaptive
// NMS - edge groups, group affinities, box score with the inner-box subtraction and boundary-
// crossing removal, the sliding-window grid with a per-region stride factor (the multistride
// change, §4.2.6), refinement and NMS. Our own implementation.
#pragma once

#include <chrono>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

class WindowAdmission;

struct EdgeBoxParams {
  float alpha = 0.65f;  // step / IoU between neighbouring windows
  float beta = 0.75f;   // NMS IoU
  float min_score = 0.01f;
  int max_boxes = 10000;  // after NMS
  float edge_min_mag = 0.1f;
  float edge_merge_thr = 0.5f;
  float cluster_min_mag = 0.5f;
  float max_aspect_ratio = 6.f;  // tau_a
  float min_box_area = 100.f;    // paper: windows "from 100 pixels" (code: 60)
  float gamma = 2.f;             // affinity exponent
  float kappa = 1.5f;            // size normalisation exponent
  float stride_factor = 1.f;     // MS: (K - k + 1) / K for region k; 1 = plain sliding window
  int min_stride = 2;            // px
  // The wide side's bound on w / h (ours; 0 = tau_a, the paper's grid, symmetric about square).
  // Obstacles lying on the road are seen at a grazing angle, foreshortened in height.
  float max_wide_aspect_ratio = 0.f;
  bool refine = true;
  // Edge Boxes and the paper refine every window with a non-zero score (the defaults here).
  // Two APPROXIMATIONS narrow that down; windows left out keep their grid box and score:
  // refine_local_maxima refines only the windows whose grid score no grid neighbour of the same
  // shape (one stride away in x, y or both) exceeds - with dense strides neighbouring windows
  // climb to the same box, so most refinement is repeated work; refine_limit N > 0 then keeps
  // only the N best of those by grid score (0 = no limit). See bench_pipeline_proposals and the
  // docs/method.md#local-maxima-refinement for the measured speed / recall trade-off.
  bool refine_local_maxima = false;
  int refine_limit = 0;
  // Worker threads for the window grid: 1 = the calling thread only, 0 = all hardware threads.
  // The output is identical for every value (deterministic merge, §4.2.8 NMS on a total order).
  int threads = 1;
  // Frame budget (issue 11): past this point the scan stops handing out grid columns and
  // refinements; windows of the columns not scanned are not proposed, windows not refined keep
  // their grid box, and EdgeBoxStats::truncated says so. Column chunks are handed out in a
  // scattered order when a deadline is set, so what a cut-short scan leaves out is spread over
  // every window shape and position (a coarser grid) instead of being its last shapes. The
  // default, no deadline, scans everything in grid order.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
};

// Checks every field (ranges named in the message); ScoreEdgeBoxes returns no boxes for
// parameters this rejects, so callers should validate configuration once up front.
Status ValidateEdgeBoxParams(const EdgeBoxParams& params);

// Work counters of one ScoreEdgeBoxes call (for benchmarks and logs).
struct EdgeBoxStats {
  long long edge_pixels = 0;              // map pixels > edge_min_mag (what the groups are made of)
  long long edge_groups = 0;              // edge groups after dissolving the weak ones
  long long windows_visited = 0;          // grid windows scored (only admitted ones, with one)
  long long windows_past_early_exit = 0;  // grid windows that reached the boundary-affinity walk
  long long windows_nonzero = 0;          // grid windows with a final score > 0
  long long windows_refined = 0;          // of those, refined (all unless refine_limit)
  long long scorings = 0;                 // all scorings past the early exit, with refinement
  long long boxes_out = 0;                // after NMS / max_boxes
  // The deadline cut the scan short: column chunks never scanned and refinements skipped.
  bool truncated = false;
  long long columns_skipped = 0;
  long long refinements_skipped = 0;
};

// edge_map: the region's occlusion-edge map normalised to max 1 (call NormaliseToMax first).
// Returns region-relative boxes sorted by score, descending, after NMS.
// Box convention: Edge Boxes scores the inclusive pixel range [c0, c1] x [r0, r1] (its "w" is
// c1 - c0); we return the same pixel set as a half-open Box {c0, r0, c1 - c0 + 1, r1 - r0 + 1},
// so ScoreSingleBox(returned box) reproduces the returned score.
std::vector<ScoredBox> ScoreEdgeBoxes(const cv::Mat1f& edge_map, const EdgeBoxParams& params);
std::vector<ScoredBox> ScoreEdgeBoxes(const cv::Mat1f& edge_map, const EdgeBoxParams& params,
                                      EdgeBoxStats* stats);
// With `admission` (may be null), windows that cannot end as a box the size filter keeps are not
// scored (see WindowAdmission); the caller still filters the output.
std::vector<ScoredBox> ScoreEdgeBoxes(const cv::Mat1f& edge_map, const EdgeBoxParams& params,
                                      EdgeBoxStats* stats, const WindowAdmission* admission);

// Scores one given box on the map (the same score the sliding window gives, no refinement).
// The box is clipped to the map; 0 for an empty box, empty map or invalid parameters.
float ScoreSingleBox(const cv::Mat1f& edge_map, const Box& box, const EdgeBoxParams& params);

// The largest finite value of the map (NaN and inf ignored); 0 for an empty or all-zero map.
float MaxFiniteValue(const cv::Mat1f& map);
// M / max(M), max = MaxFiniteValue(M) (unchanged when max is 0).
cv::Mat1f NormaliseToMax(const cv::Mat1f& map);

// §3.2(4): zero boundary pixels on the outermost rows / columns of a region crop that merely run
// along the crop border (prevents artificial frame edges). Applied for regions k >= 2.
void ClearCropBorderEdges(cv::Mat1f& region_map);

// Greedy NMS: keeps a box if its IoU with every kept box is <= iou_threshold; input any order,
// output sorted by score descending, at most max_boxes.
std::vector<ScoredBox> NonMaximumSuppression(std::vector<ScoredBox> boxes, float iou_threshold,
                                             int max_boxes);

}  // namespace tod
