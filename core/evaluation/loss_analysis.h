// `tod analyse`: where the obstacles of an annotated split are lost on the way through the
// pipeline. Per ground-truth obstacle: is its contour in the base edge map and in the occlusion
// edge map, is any proposal a hit before and after the size filter, is a hit among the first 1000
// proposals by objectness, and among the first 1000 by regressed score. Per frame: how dense the
// edge maps are and how much work the proposal stage does, and how the fused scores of the boxes
// on an obstacle compare with those of the boxes on none. Over the split: where the pixel AP of
// the paper's map (BP+Fusion@4) goes (PixelApBreakdown). This is how the figures of
// docs/findings.md#where-the-pixel-ap-goes were found; it runs the pipeline's own stage functions.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/datasets/dataset_selection.h"
#include "core/pipeline/model_bundle.h"

namespace tod {

struct LossAnalysisOptions {
  DatasetSelection data;  // the test split by default; skipped frames are left out of every count
  int threads = 0;
  double hit_iou = 0.5;  // a proposal "finds" an obstacle at box IoU >= this
  int top_n = 1000;      // the paper's largest proposal budget
  std::function<void(const std::string&)> progress;
};

struct ObstacleFate {
  std::string frame;
  Box box;
  long long pixels = 0;
  int range = 0;                   // vertical range of its bottom row (0 = nearest)
  bool in_r1 = false;              // its box lies inside R1
  double contour_base_edges = 0;   // share of contour pixels with E > 0.1 within 1 px
  double contour_occlusion = 0;    // the same on the occlusion edge map
  double best_iou_unfiltered = 0;  // best box IoU of any proposal of any region, no size filter
  double best_iou_filtered = 0;    // the same through the size filter (what the detector keeps)
  int proposal_rank = -1;          // first hit in the merged objectness ranking, -1 none
  int regressed_rank = -1;         // first hit in the fused-score ranking, -1 none
};

struct FrameWork {
  std::string frame;
  double base_edge_density = 0;  // share of R1 pixels with E > 0.1
  double occlusion_density = 0;  // share of R1 pixels with occlusion edge > 0.1
  int superpixels = 0;
  long long windows_scored = 0;  // over the K regions, size filter admission on
  long long proposals = 0;       // after the size filter, all regions
  // Fused scores F (§6.5) of the proposals: the best of a box that covers an obstacle pixel, the
  // best of a box that covers none (a false box), and how many false boxes score above the
  // best box on an obstacle.
  float best_obstacle_box_score = 0.f;
  float best_false_box_score = 0.f;
  long long false_boxes_above = 0;
};

// Pixel AP of the paper's map (§7) of BP+Fusion@4 over the split, pooled as `tod eval` pools it,
// from the same proposals with three scorings: as served; with every false box (one that covers
// no obstacle pixel) scored 0, i.e. what rejecting the false boxes perfectly would give; and
// with the fused score perfect regressors would give, ORDR = OBDR = the box's mask IoU (§6.4),
// gated and fused as served. The gap between the first two is what the false boxes cost, the
// gap to the third what the scores cost in all; what the third misses, the proposals and the
// map's shape do.
struct PixelApBreakdown {
  double served = 0;
  double false_boxes_removed = 0;
  double perfect_scores = 0;
};

struct LossAnalysis {
  std::vector<ObstacleFate> obstacles;
  std::vector<FrameWork> frames;
  PixelApBreakdown pixel_ap;
};

Result<LossAnalysis> AnalyseLosses(const ModelBundle& bundle, const LossAnalysisOptions& options);

// Funnel table (share of obstacles still found after each step, overall and by height band) and
// the medians of the frame counters, as text.
std::string FormatLossAnalysis(const LossAnalysis& analysis, const LossAnalysisOptions& options);
nlohmann::json LossAnalysisToJson(const LossAnalysis& analysis);

}  // namespace tod
