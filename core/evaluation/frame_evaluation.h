// What one frame contributes to `tod eval` (evaluator.h): every variant's ranked boxes, every
// pixel-metric variant's map, the obstacles the detector reports and the stage times of the
// detector's own path. Computed without any shared state, so frames run side by side and
// EvaluateModel only adds the results up.
#pragma once

#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/base/stage_timer.h"
#include "core/base/status.h"
#include "core/base/types.h"
#include "core/evaluation/obstacle_list_sweep.h"
#include "core/metrics/component_metrics.h"
#include "core/pipeline/obstacle_detector.h"

namespace tod {

// Proposals per frame that average recall counts (AR@1000, the paper's N) and the EB baseline
// is asked for.
inline constexpr int kEvalMaxProposals = 1000;

inline const std::vector<std::string>& ProposalVariants() {
  static const std::vector<std::string> v = {"EB", "OLP@1", "OAOCC+OLP@1", "OAOCC+OLP@4",
                                             "OAOCC+OLP@4+MS"};
  return v;
}
inline const std::vector<std::string>& RegressionVariants() {
  static const std::vector<std::string> v = {"OP+ORDR@4", "BP+ORDR@4", "BP+Fusion@4"};
  return v;
}

// The calibrated map (probability_map.h) of BP+Fusion@4's boxes, evaluated beside the paper's
// maps when the bundle has a fitted calibration. It ranks the same boxes, so it has pixel metrics
// but no recall of its own.
inline constexpr const char* kCalibratedMapVariant = "BP+Fusion@4 cal";

struct FrameEvaluation {
  // Per recall variant (ProposalVariants() and RegressionVariants()), its boxes best first.
  std::map<std::string, std::vector<Box>> ranked;
  // Per pixel-metric variant, its map, in the order of PixelMapVariants: RegressionVariants(),
  // then kCalibratedMapVariant when the bundle has a fitted calibration.
  std::vector<std::pair<std::string, cv::Mat1f>> maps;
  // The obstacles the detector reports at its defaults (DetectOptions{}).
  ObstacleListCounts reported;
  FrameComponents reported_components;  // SMIYC components of the reported obstacles' pixels
  // The same counts under other reporting rules (obstacle_list_sweep.h).
  std::map<std::string, ObstacleListCounts> list_sweep;
  // The detector's path (edges to the BP+Fusion map), timed stage by stage; the baselines and
  // the other variants run outside it.
  StageTimes stage_times;
  double total_ms = 0;
  HorizonUse horizon;  // the geometry the detector stood on (self-calibration)
};

// The detector's own path comes from one Detect call (its FrameTrace); the baselines and the
// paper's other variants are computed beside it from that trace. `options`: the detector's
// defaults, except for how the geometry is calibrated (DetectOptions::calibrate, ::camera).
Result<FrameEvaluation> EvaluateFrame(const ObstacleDetector& detector, const Sample& sample,
                                      const DetectOptions& options = {});

}  // namespace tod
