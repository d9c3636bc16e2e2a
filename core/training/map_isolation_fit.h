// Fits the probability map's isolation exponent (box_isolation.h) on training frames: each
// candidate exponent's map is built from the same out-of-fold fused boxes, its pixels pooled as
// `tod eval` pools BP+Fusion@4 (obstacle against free space), and the exponent whose map has the
// highest pixel AP wins (ties: the smaller one, the nearer the paper's map). The obstacles each
// candidate yields (from ObstacleComponentsMap, as the detector takes them) are kept too, so
// that the score calibration is fitted on the components the bundle will report.
#pragma once

#include <mutex>
#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/metrics/pixel_histogram_metrics.h"
#include "core/pipeline/pipeline_params.h"
#include "core/pipeline/probability_map.h"

namespace tod {

// The candidates `tod train` tries: the paper's map (0) and isolation to growing powers.
std::vector<float> DefaultIsolationExponents();

class MapIsolationFit {
 public:
  // `params`: the bundle's parameters, whose map every candidate shares but for the exponent.
  // `frames`: frame indexes run from 0 to frames - 1.
  MapIsolationFit(std::vector<float> exponents, const PipelineParams& params, int frames);

  // One training frame's fused boxes (every proposal, F = 0 where gated out). Thread-safe; each
  // frame index at most once.
  // `superpixels`: the frame's, for a map that weighs boxes by superpixel shares.
  Status AddFrame(int frame, const Sample& sample, const MapSuperpixels& superpixels,
                  const std::vector<ScoredBox>& fused);

  // The index of the winning candidate (call after every frame was added).
  int Best() const;
  float exponent(int candidate) const { return exponents_[candidate]; }
  // (evidence, covers an obstacle pixel) of every component the candidate's map yields, by frame.
  std::vector<std::pair<double, int>> Components(int candidate) const;
  // {"candidates": [{"exponent", "ap"}...], "exponent": the winner's}.
  nlohmann::json ToJson() const;

 private:
  std::vector<float> exponents_;
  PipelineParams params_;
  std::vector<PixelHistogramAccumulator> pixels_;  // per candidate
  // [candidate][frame]: the frame's components under that candidate's map.
  std::vector<std::vector<std::vector<std::pair<double, int>>>> components_;
  mutable std::mutex mutex_;
};

}  // namespace tod
