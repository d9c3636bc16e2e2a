// Lost and Found reader (ALGORITHM.md §9.1):
//   <root>/leftImg8bit/<split>/<scene>/<stem>_leftImg8bit.png
//   <root>/gtCoarse/<split>/<scene>/<stem>_gtCoarse_{labelIds,instanceIds}.png
// instanceIds: 1000 = free space (road), > 1000 = obstacle instance, < 1000 = ignore.
// labelIds must agree (1 <-> 1000, >= 2 <-> > 1000); a disagreement names the file.
#pragma once

#include <memory>
#include <string>

#include "core/data/dataset.h"

namespace tod {

// Lists every frame of `split` ("train" / "test") under `root`, sorted by path. Fails with a
// message naming the missing directory or the image whose annotation files are missing.
Result<std::unique_ptr<Dataset>> OpenLafDataset(const std::string& root, const std::string& split);

// True when `root` looks like the Lost and Found layout (has leftImg8bit/ and gtCoarse/).
bool LooksLikeLaf(const std::string& root);

// Builds a Sample from an image and its two annotation images (exposed for tests).
Result<Sample> SampleFromLafAnnotation(const cv::Mat3b& image, const cv::Mat& instance_ids,
                                       const cv::Mat& label_ids, const std::string& name,
                                       const std::string& source_for_messages);

}  // namespace tod
