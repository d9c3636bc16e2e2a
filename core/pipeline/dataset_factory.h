// Opens a dataset split by format: "laf" (Lost and Found layout, also `tod synth` output),
// "modd2" (MODDv2), or "auto" (detected from the layout).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/data/dataset.h"

namespace tod {

Result<std::unique_ptr<Dataset>> OpenDataset(const std::string& root, const std::string& split,
                                             const std::string& format = "auto");

// At most `count` indices of [0, total) spread evenly, ascending (all of them when count <= 0 or
// count >= total), so a subset still covers every scene.
std::vector<int> SpreadIndices(int total, int count);

// A split opened for training or evaluation, with the frames to use: all of them, or at most
// max_frames spread evenly over the split (so a subset still covers every scene).
struct FrameSelection {
  std::unique_ptr<Dataset> dataset;
  std::string format;       // resolved: "laf" or "modd2"
  std::vector<int> frames;  // indices into dataset, ascending, never empty
};
Result<FrameSelection> SelectFrames(const std::string& root, const std::string& split,
                                    const std::string& format, int max_frames);

// "laf", "modd2", or an error naming what was looked for.
Result<std::string> DetectDatasetFormat(const std::string& root);

}  // namespace tod
