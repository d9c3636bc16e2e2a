// The sticky-superpixel label refinement (ALGORITHM.md §3.2(1)): boundary pixels move to the
// neighbouring label of least cost, a k-means-like step whose cost also rewards boundaries that
// lie on strong edges and favours large superpixels.
#pragma once

#include <vector>

namespace tod {

// Cost weights. cost(t) = position·‖xy − μ_t‖² + colour·‖c − μ_t‖² − edge·e_t + size/|t|.
struct StickyWeights {
  double size = 0.0;
  double position = 0.0;
  double edge = 0.0;
  double colour = 0.0;
};

// Weights of §3.2(1) from the user parameters: size = k·α/1e4, position = α/1e4,
// edge = (1−α)·β, colour = (1−α)·(1−β).
StickyWeights StickyWeightsFor(int k, double alpha, double beta);

// A flat view of one resolution level: colour is interleaved 3 floats per pixel.
struct StickyImage {
  int width = 0;
  int height = 0;
  const float* colour = nullptr;  // width·height·3
  const float* edge = nullptr;    // width·height
};

// Refines `labels` (width·height non-negative ids, any range) in place for at most `iterations`
// sweeps; stops early when a sweep changes nothing. Returns the number of sweeps run.
int RefineStickyLabels(const StickyImage& image, const StickyWeights& weights, int iterations,
                       std::vector<int>& labels);

}  // namespace tod
