#include "server/core/image_codec.h"

#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "server/core/image_header.h"

namespace tod::server {

Result<cv::Mat3b> DecodeImage(std::string_view bytes, const ImageLimits& limits) {
  if (bytes.empty()) return Status::InvalidArgument("image: empty body, expected a JPEG or PNG");
  if (bytes.size() > limits.max_bytes) {
    return Status::ResourceExhausted("image: " + std::to_string(bytes.size()) +
                                     " bytes is over the limit of " +
                                     std::to_string(limits.max_bytes) + " bytes");
  }
  Result<ImageHeader> header = PeekImageHeader(bytes);
  if (!header.ok()) return header.status();
  const long long pixels = static_cast<long long>(header->size.width) * header->size.height;
  if (pixels > limits.max_pixels) {
    return Status::ResourceExhausted("image: " + std::to_string(header->size.width) + "x" +
                                     std::to_string(header->size.height) + " = " +
                                     std::to_string(pixels) + " pixels is over the limit of " +
                                     std::to_string(limits.max_pixels) + " pixels");
  }
  // cv::imdecode takes a Mat header over the bytes; it does not modify them.
  const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1,
                        const_cast<char*>(bytes.data()));
  cv::Mat decoded;
  try {
    decoded = cv::imdecode(encoded, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    return Status::InvalidArgument(std::string("image: decoder failed: ") + e.what());
  }
  if (decoded.empty() || decoded.type() != CV_8UC3) {
    return Status::InvalidArgument("image: could not decode " + std::to_string(bytes.size()) +
                                   " bytes as JPEG/PNG (corrupt or truncated)");
  }
  return cv::Mat3b(decoded);
}

Result<std::string> EncodeProbabilityPng(const cv::Mat1f& probability) {
  if (probability.empty()) return Status::Internal("probability map is empty");
  cv::Mat1b grey;
  // convertTo saturates, so values outside [0, 1] clamp to 0 / 255.
  probability.convertTo(grey, CV_8U, 255.0);
  std::vector<uchar> png;
  if (!cv::imencode(".png", grey, png)) return Status::Internal("PNG encoder failed");
  return std::string(png.begin(), png.end());
}

}  // namespace tod::server
