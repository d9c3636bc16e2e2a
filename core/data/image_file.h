// Reading one image file for a dataset reader, with errors that tell a missing file from one that
// exists but does not decode.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "core/base/status.h"

namespace tod {

// cv::imread(path, flags); NotFound when there is no such file, DataLoss when it does not decode.
// `what` names the file's role in messages ("image", "instanceIds", "mask").
Result<cv::Mat> ReadImageFile(const std::string& path, int flags, const std::string& what);

}  // namespace tod
