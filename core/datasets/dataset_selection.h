// Which frames a command reads and what an unreadable one does: one struct for `tod train`
// (TrainOptions), `tod eval` (EvalOptions) and `tod analyse` (LossAnalysisOptions), so the three
// cannot drift in what they accept.
#pragma once

#include <string>
#include <utility>

#include "core/datasets/bad_frames.h"
#include "core/datasets/dataset_factory.h"

namespace tod {

struct DatasetSelection {
  std::string data_root;
  std::string format = "auto";  // auto | laf | masks | modd2
  std::string split = "test";
  std::string split_file;  // masks: `train|test <stem>` lines instead of <data_root>/split.txt
  int max_frames = 0;      // at most this many, spread evenly over the split (0 = all)
  BadFramePolicy on_bad_frame = BadFramePolicy::kFail;

  DatasetSpec Spec() const { return {data_root, split, format, split_file, max_frames}; }
};

// The defaults with another split ("train" for `tod train`).
inline DatasetSelection SelectionOfSplit(std::string split) {
  DatasetSelection selection;
  selection.split = std::move(split);
  return selection;
}

}  // namespace tod
