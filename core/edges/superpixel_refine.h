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
//
// The sweeps run in raster order. With more than one thread (cv::getNumThreads), as many sweeps at
// once as there are threads: each starts while the one before it is still running and follows it
// down the rows, moving a pixel only once no sweep ahead can read or change any label that move
// reads (every such label lies above the two rows next to the current row of the sweep just ahead;
// a bound on each label's last row is kept as pixels join it). The moves are then exactly those of
// the sweeps one after the other, so the labels are bit-identical to one thread's (the
// reference): only the serial sweeps' time is shared between cores.
int RefineStickyLabels(const StickyImage& image, const StickyWeights& weights, int iterations,
                       std::vector<int>& labels);

}  // namespace tod
