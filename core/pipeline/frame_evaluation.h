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
#include "core/pipeline/model_bundle.h"

namespace tod {

struct FrameEvaluation {
  // Per recall variant (ProposalVariants() and RegressionVariants()), its boxes best first.
  std::map<std::string, std::vector<Box>> ranked;
  // Per pixel-metric variant, its map, in the order of PixelMapVariants: RegressionVariants(),
  // then kCalibratedMapVariant when the bundle has a fitted calibration.
  std::vector<std::pair<std::string, cv::Mat1f>> maps;
  int false_alarms = 0;     // reported obstacles without a ground-truth obstacle pixel
  int instances_found = 0;  // ground-truth instances that a reported obstacle overlaps
  // The detector's path (edges to the BP+Fusion map), timed stage by stage; the baselines and
  // the other variants run outside it.
  StageTimes stage_times;
  double total_ms = 0;
};

Result<FrameEvaluation> EvaluateFrame(const ModelBundle& bundle, const Sample& sample);

}  // namespace tod
