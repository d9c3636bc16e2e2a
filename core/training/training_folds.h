// How `tod train` deals its frames into the folds of stacked training (out-of-fold maps and the
// score calibration's cross-fitting; trainer.cc).
#pragma once

#include <vector>

namespace tod {

// The fold (0 .. folds-1) of every frame position in [0, num_frames); -1 for positions that are
// not in `usable`. source[i]: the dataset position i comes from (empty: one dataset).
// Each fold is one contiguous run of the split's frames, in the split's order. Datasets list the
// frames of a drive in order (Lost and Found by sequence and frame, mask sets by natural stem
// order), and neighbouring frames of a drive are near-duplicates, so a fold of whole runs leaves a
// frame's neighbours out of its fold's training as a new drive's frame would be
// (docs/findings.md#folds-as-runs-of-consecutive-frames). Each dataset's usable positions are cut
// into `folds` runs as even as possible, so that with several datasets (`tod train --add-data`)
// every fold holds part of each rather than one fold one dataset.
std::vector<int> AssignFolds(int num_frames, const std::vector<int>& usable, int folds,
                             const std::vector<int>& source = {});

// The manifest's name of that layout, recorded per part ("fold_layout"). Frames dealt in turn
// ("alternate") were measured and removed; a bundle that records them is refused at load
// (removed_options.h).
inline constexpr const char* kFoldLayoutName = "blocks";

}  // namespace tod
