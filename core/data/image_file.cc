#include "core/data/image_file.h"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <system_error>

namespace tod {

Result<cv::Mat> ReadImageFile(const std::string& path, int flags, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::NotFound(what + " file not found: " + path);
  }
  cv::Mat m;
  try {
    m = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    return Status::DataLoss("cannot decode " + what + " " + path + ": " + e.what());
  }
  if (m.empty()) return Status::DataLoss("cannot decode " + what + ": " + path);
  return m;
}

}  // namespace tod
