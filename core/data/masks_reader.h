// Reader for the obstacle/anomaly benchmark layout (Fishyscapes Lost & Found, SegmentMeIfYouCan
// RoadObstacle21 / Obstacle Track):
//   <root>/images/<stem>.{png,jpg,jpeg,webp}
//   <root>/labels_masks/<stem>.png  or  <root>/labels_masks/<stem>_labels_semantic.png
// Masks are single-channel 8-bit: 0 = not an obstacle, 1 = obstacle, 255 = void. Obstacle
// instances are the 8-connected components of 1; components under kMinInstancePixels become void.
// These sets have no road label, so `road` holds every pixel that is neither obstacle nor void
// (Sample::free_space = FreeSpace::kNotObstacle), as their evaluation convention counts it.
//
// The split: an optional <root>/split.txt (or a file given explicitly) with `train <stem>` /
// `test <stem>` lines ('#' starts a comment). Without one, every split name takes every frame.
// With one, a split takes the stems listed under its name, or every listed frame for "all".
#pragma once

#include <memory>
#include <string>

#include "core/data/dataset.h"

namespace tod {

inline constexpr int kMinInstancePixels = 10;

// Lists the frames of `split`. split_file: a split file to use instead of <root>/split.txt (empty:
// use <root>/split.txt when it exists). Fails naming the missing directory, an image without a
// mask, a stem listed in the split file without an image, or a malformed split line.
Result<std::unique_ptr<Dataset>> OpenMasksDataset(const std::string& root, const std::string& split,
                                                  const std::string& split_file = "");

// True when `root` has images/ and labels_masks/.
bool LooksLikeMasks(const std::string& root);

// Builds a Sample from an image and its {0, 1, 255} mask (exposed for tests).
Result<Sample> SampleFromObstacleMask(const cv::Mat3b& image, const cv::Mat& mask,
                                      const std::string& name, const std::string& mask_source);

}  // namespace tod
