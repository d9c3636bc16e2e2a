#include "core/data/image_file.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <system_error>

#include "core/data/plain_png.h"

namespace tod {

Result<std::string> ReadFileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::NotFound("cannot open " + path);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) return Status::DataLoss("cannot read " + path);
  return bytes;
}

Result<cv::Mat3b> DecodeColourImage(std::string_view bytes) {
  if (IsPlainPng(bytes)) return DecodePlainPng(bytes, kMaxFilePixels);
  cv::Mat decoded;
  try {
    const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8U,
                          const_cast<char*>(bytes.data()));  // read only: imdecode copies out
    decoded = cv::imdecode(encoded, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    return Status::InvalidArgument(std::string("image: cannot decode: ") + e.what());
  }
  if (decoded.empty()) return Status::InvalidArgument("image: not a decodable image");
  return cv::Mat3b(decoded);
}

Result<cv::Mat> ReadImageFile(const std::string& path, int flags, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::NotFound(what + " file not found: " + path);
  }
  if (flags == cv::IMREAD_COLOR) {
    const Result<std::string> bytes = ReadFileBytes(path);
    if (!bytes.ok()) return Status::DataLoss("cannot read " + what + ": " + path);
    Result<cv::Mat3b> image = DecodeColourImage(*bytes);
    if (!image.ok()) {
      return Status::DataLoss("cannot decode " + what + " " + path + ": " +
                              image.status().message());
    }
    return cv::Mat(std::move(image).value());
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
