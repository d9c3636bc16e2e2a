// Pasted obstacles (not in the paper; README "Real frames"): a training frame with obstacles of
// other training frames pasted onto it, a cheap way to show the regressors each obstacle in more
// surroundings when a training split holds a few dozen obstacles. An obstacle is cut out with a
// ring of its own road (its contact shadow and its own boundary against the ground stay real; the
// seam lies in road, feathered) and pasted at its own row, shifted sideways: the row keeps its
// size right for the camera, since frames of one split share one camera. It is only placed where
// the target frame has free space under the whole cut-out, so it never covers an obstacle or void.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/types.h"

namespace tod {

struct PasteParams {
  int obstacles_per_frame = 2;      // pasted into each copy (fewer when no place is free)
  double max_shift_fraction = 0.2;  // sideways shift, at most this share of the frame width
  double margin_fraction = 0.25;    // ring of own road, this share of the obstacle's larger side
  int min_margin = 3;               // pixels
  int tries = 20;                   // shifts tried per obstacle; the best-matching one is taken
  // A shift is only taken when the road ring differs from what it covers by at most this much
  // (mean absolute difference, grey levels): the ring should land on the same kind of surface.
  double max_ring_difference = 20.0;
};

// An obstacle cut out of its frame: the cut-out's pixels, where the obstacle is in it, and how
// much of each pixel is pasted (1 inside the obstacle, falling to 0 across the road ring).
struct ObstacleCutout {
  int frame = -1;   // the frame (training position) it comes from
  Box box;          // the cut-out in its frame's coordinates
  cv::Mat3b patch;  // box.h x box.w
  cv::Mat1b mask;   // 255 = obstacle
  cv::Mat1f alpha;  // in [0, 1]
};

// The cut-out of `instance` of `sample`, clipped to the frame; empty patch when the instance is
// empty or its ring would reach void or another obstacle (such a cut-out would carry them along).
ObstacleCutout CutOutObstacle(const Sample& sample, const ObstacleInstance& instance, int frame,
                              const PasteParams& params);

// A copy of `target` with up to params.obstacles_per_frame of `donors` pasted, chosen and placed
// by `seed` (deterministic): each at its own row, shifted sideways, where every pixel under its
// cut-out is free space of the target (and of what was pasted before), at the tried shift whose
// surface matches the cut-out's road ring best. The
// pasted obstacles are instances of the copy, their pixels obstacle and no longer free space. The
// name gets "+pasted".
Sample PasteObstacles(const Sample& target, const std::vector<const ObstacleCutout*>& donors,
                      std::uint64_t seed, const PasteParams& params);

// Makes the first `own` instances of `pasted` (the target's own obstacles) void, so that the
// copy's obstacles are the pasted ones only.
void VoidOwnObstacles(Sample& pasted, std::size_t own);

}  // namespace tod
