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
//
// The provisional scan (an option, off by default; the result is the same either way): when
// refinement is off or limited to the refine_limit best local maxima, and the grid has at least
// kMinGridWindowsPerBox * max_boxes windows, the grid is first scanned keeping only windows that
// score above provisional_bar * min_score. That result is the exact one whenever NMS still fills
// up to max_boxes and at least refine_limit local maxima remain (every removed window scores
// below every kept one); otherwise the grid is scanned again without the bar (stats.rescans).
// provisional_bar <= 1 turns it off. It paid on the synthetic frames it was tuned on (no region
// rescanned, ~10 % fewer walks); with models trained on real frames NMS rarely fills max_boxes,
// so 11 of 12 real regions and 15 of 16 synthetic ones were scanned twice and the proposal stage
// took ~1.4x as long (README, Speed): ScanWindowGrid's default is off.
inline constexpr float kProvisionalBar = 1.5f;
inline constexpr long long kMinGridWindowsPerBox = 100;
std::vector<ScoredBox> ScanWindowGrid(const BoxScorer& scorer, const EdgeBoxParams& params,
                                      EdgeBoxStats& stats,
                                      const WindowAdmission* admission = nullptr,
                                      float provisional_bar = 0.f);

// Threads actually used for a request: 0 = std::thread::hardware_concurrency() (at least 1).
int ResolveThreadCount(int requested);

}  // namespace tod
