// The sliding-window pass of OLP (ALGORITHM.md §4.2 steps 4-8): every grid window is scored,
// those with a non-zero score are refined and NMS selects the output. Optionally split over
// threads; the result does not depend on the thread count.
#pragma once

#include <vector>

#include "core/base/types.h"
#include "core/proposals/box_scorer.h"
#include "core/proposals/edge_box_scorer.h"

namespace tod {

// The boxes after NMS: every window with a non-zero score refined (or the refine_limit best, see
// EdgeBoxParams), listed in grid order (shape, column, row) and passed to NonMaximumSuppression;
// as half-open boxes of the scored pixel set. `threads` as in EdgeBoxParams (0 = all hardware
// threads). Fills the counters of `stats` except boxes_out. Each thread works on its own copy of
// `scorer`.
// With `admission`, windows that cannot end as a box the size filter keeps are not scored.
// (A provisional scan above a score bar, rescanning where it did not settle, was measured and
// removed: docs/findings.md#provisional-scan.)
std::vector<ScoredBox> ScanWindowGrid(const BoxScorer& scorer, const EdgeBoxParams& params,
                                      EdgeBoxStats& stats,
                                      const WindowAdmission* admission = nullptr);

// Threads actually used for a request: 0 = std::thread::hardware_concurrency() (at least 1).
int ResolveThreadCount(int requested);

}  // namespace tod
