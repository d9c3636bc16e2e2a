// Opens a dataset split by format: "laf" (Lost and Found layout, also `tod synth` output),
// "masks" (obstacle benchmark masks: images/ + labels_masks/), "modd2" (MODDv2), or "auto"
// (detected from the layout).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/data/dataset.h"

namespace tod {

// Which frames of which dataset.
struct DatasetSpec {
  std::string root;
  std::string split = "train";
  std::string format = "auto";  // auto, laf, masks, modd2
  std::string split_file;       // masks only: instead of <root>/split.txt
  int max_frames = 0;           // at most this many, spread evenly over the split (0 = all)
};

Result<std::unique_ptr<Dataset>> OpenDataset(const DatasetSpec& spec);

// At most `count` indices of [0, total) spread evenly, ascending (all of them when count <= 0 or
// count >= total), so a subset still covers every scene.
std::vector<int> SpreadIndices(int total, int count);

// A split opened for training or evaluation, with the frames to use: all of them, or at most
// max_frames spread evenly over the split (so a subset still covers every scene).
struct FrameSelection {
  std::unique_ptr<Dataset> dataset;
  std::string format;       // resolved: "laf", "masks" or "modd2"
  std::vector<int> frames;  // indices into dataset, ascending, never empty
  // Per entry of `frames`: which of the datasets it comes from (all 0 for one dataset), so that
  // whatever follows a dataset's order (training_folds.h) can stay within it.
  std::vector<int> source;
};
Result<FrameSelection> SelectFrames(const DatasetSpec& spec);
// Several datasets as one (e.g. synthetic scenes and real frames): their selections in order;
// frame names are prefixed with the dataset's position when there is more than one.
Result<FrameSelection> SelectFrames(const std::vector<DatasetSpec>& specs);

// "laf", "masks", "modd2", or an error naming what was looked for.
Result<std::string> DetectDatasetFormat(const std::string& root);

}  // namespace tod
