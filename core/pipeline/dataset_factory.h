// Opens a dataset split by format: "laf" (Lost and Found layout, also `tod synth` output),
// "modd2" (MODDv2), or "auto" (detected from the layout).
#pragma once

#include <memory>
#include <string>

#include "core/data/dataset.h"

namespace tod {

Result<std::unique_ptr<Dataset>> OpenDataset(const std::string& root, const std::string& split,
                                             const std::string& format = "auto");

// "laf", "modd2", or an error naming what was looked for.
Result<std::string> DetectDatasetFormat(const std::string& root);

}  // namespace tod
