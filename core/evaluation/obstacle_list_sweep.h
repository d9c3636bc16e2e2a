// How the obstacle list would fare under other reporting rules, measured on the same frames in
// the same `tod eval` run: the detector reports the components of its whole-box map over
// DetectOptions::obstacle_threshold whose calibrated score reaches min_obstacle_score; the sweep
// counts, for a grid of both, and for a list made of the map's boxes themselves (best first,
// nested and overlapping boxes suppressed), what ReportedObstacleCounts counts for the served
// list. It re-reads the frame's trace only, so the grid costs no detector time.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/types.h"
#include "core/pipeline/detector.h"
#include "core/pipeline/frame_trace.h"
#include "core/pipeline/model_bundle.h"

namespace tod {

// One list's counts on a frame or, summed, on a split.
struct ObstacleListCounts {
  int reported = 0;
  int false_alarms = 0;     // reported boxes without a ground-truth obstacle pixel
  int instances_found = 0;  // ground-truth instances a reported box overlaps
  int found_iou25 = 0;      // ... matches at box IoU >= 0.25
  int found_iou50 = 0;      // ... at box IoU >= 0.5
  ObstacleListCounts& operator+=(const ObstacleListCounts& o);
};

// `boxes` against the frame's ground truth.
ObstacleListCounts CountObstacleList(const Sample& sample, const std::vector<Box>& boxes);

// The list of `map_boxes` as obstacles: best calibrated score first, a box dropped when it
// overlaps a kept one by more than half of the smaller of the two, boxes of fewer than
// `min_area` pixels or below `min_score` left out.
std::vector<DetectedObstacle> BoxListObstacles(const std::vector<ScoredBox>& map_boxes,
                                               const PipelineParams& params, float min_score,
                                               int min_area);

struct ObstacleListSweepGrid {
  std::vector<float> thresholds = {0.1f, 0.2f, 0.3f, 0.5f};  // of the whole-box map (peak 1)
  std::vector<float> calibrated_thresholds = {0.3f, 0.5f};   // of the calibrated map
  std::vector<float> min_scores = {0.1f, 0.2f, 0.3f, 0.5f};
};

// Keyed "components@T/S" (whole-box map threshold T, minimum score S), "calibrated@T/S" (the
// components of the calibrated map, when `calibrated` is given) and "boxes/S".
std::map<std::string, ObstacleListCounts> SweepObstacleLists(
    const Sample& sample, const FrameTrace& trace, const PipelineParams& params,
    const cv::Mat1f* calibrated, const ObstacleListSweepGrid& grid = {});

// {"components@T": {"S": {found_iou50, found_iou25, instances_found, false_alarms_per_frame,
// reported_per_frame}}, "boxes": {"S": {...}}}: shares of `instances`, rates per frame.
nlohmann::json ObstacleListSweepToJson(const std::map<std::string, ObstacleListCounts>& sweep,
                                       int instances, int frames);
// The same as a table, one rule a row.
std::string FormatObstacleListSweep(const std::map<std::string, ObstacleListCounts>& sweep,
                                    int instances, int frames);

}  // namespace tod
