#include "server/core/image_codec.h"

#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "server/core/image_header.h"
#include "server/core/strict_decoders.h"

namespace tod::server {

Result<cv::Mat3b> DecodeImage(std::string_view bytes, const ImageLimits& limits) {
  if (bytes.empty()) {
    return Status::InvalidArgument("image: empty body, expected a JPEG, PNG or WebP");
  }
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
  // The decoders check their own header against the pixel limit again before allocating, so
  // nothing this function accepted can decode to more pixels than the limit allows.
  switch (header->format) {
    case ImageFormat::kJpeg:
      return DecodeJpegStrict(bytes, limits.max_pixels);
    case ImageFormat::kWebp:
      return DecodeWebpStrict(bytes, limits.max_pixels);
    case ImageFormat::kPng:
      break;
  }
  return DecodePngStrict(bytes, limits.max_pixels);
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
