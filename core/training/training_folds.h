// How `tod train` deals its frames into the folds of stacked training (out-of-fold maps and the
// score calibration's cross-fitting; trainer.cc).
#pragma once

#include <string>
#include <vector>

#include "core/base/status.h"

namespace tod {

// kSequenceBlocks: each fold is one contiguous run of the split's frames, in the split's order.
// Datasets list the frames of a drive in order (Lost and Found by sequence and frame, mask sets
// by natural stem order), and neighbouring frames of a drive are near-duplicates, so a fold of
// whole runs leaves a frame's neighbours out of its fold's training as a new drive's frame
// would be. kAlternate: frames dealt to the folds in turn (the earlier recipe): a frame's
// neighbours then train the copy that computes its maps.
enum class FoldLayout { kSequenceBlocks, kAlternate };

// "blocks" | "alternate".
Result<FoldLayout> ParseFoldLayout(const std::string& name);
const char* FoldLayoutName(FoldLayout layout);

// The fold (0 .. folds-1) of every frame position in [0, num_frames); -1 for positions that are
// not in `usable`. source[i]: the dataset position i comes from (empty: one dataset).
// kSequenceBlocks: each dataset's usable positions in order, cut into `folds` runs as even as
// possible, so that with several datasets (`tod train --add-data`) every fold holds part of each
// rather than one fold one dataset. kAlternate: the classifier frames dealt in turn in their own
// order (they are every k-th usable frame, so dealing by position could put them all in one fold),
// then the other usable frames in theirs.
std::vector<int> AssignFolds(int num_frames, const std::vector<int>& usable,
                             const std::vector<int>& classifier_frames, int folds,
                             FoldLayout layout, const std::vector<int>& source = {});

}  // namespace tod
