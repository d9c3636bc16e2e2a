// How isolated a box is among the frame's best boxes: a weight the probability map (§7) may give
// each box's score (not in the paper; docs/method.md#isolation-weighted-map).
//
// Why: on real frames the boxes that outscore the obstacles mostly frame *part* of something
// larger - a stretch of lane stripe, the grille of a car, a pedestrian's legs - and the frame's
// best proposals then crowd all along that larger thing, while those of a small lost object are
// centred on it. The regressors score one box at a time and cannot see that; the map, which
// holds all of a frame's boxes, can.
#pragma once

#include <vector>

#include "core/base/types.h"

namespace tod {

struct BoxIsolationParams {
  // Weight = isolation^exponent. 0: every weight is 1, the paper's map.
  float exponent = 0.f;
  // The frame's best boxes (by score) whose centres are counted: the paper's largest proposal
  // budget.
  int context_boxes = 1000;
  // The surround is the box grown about its centre to this many times its width and height:
  // 3 is the box and its eight neighbours of the same size.
  float surround = 3.f;
};

// For each box of `boxes`: isolation = (context centres inside the box) / (context centres inside
// its surround), in (0, 1], where the context is the `context_boxes` best of `frame_boxes` (ties in
// their order); a box holding no context centre counts one (its own). Returns isolation^exponent
// per box (all 1 when exponent is 0). Cost: boxes x context_boxes comparisons.
std::vector<float> IsolationWeights(const std::vector<ScoredBox>& boxes,
                                    const std::vector<ScoredBox>& frame_boxes,
                                    const BoxIsolationParams& params);

}  // namespace tod
