// Image bytes <-> pixels at the service edge: size limits are checked on the header before the
// decoder allocates anything.
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "core/base/status.h"

namespace tod::server {

struct ImageLimits {
  size_t max_bytes = 16u << 20;      // encoded size
  long long max_pixels = 4'000'000;  // width * height from the header
};

// Decodes a JPEG/PNG/WebP to 8-bit BGR. Empty, unrecognised, corrupt or truncated input (decoder
// warnings included) is InvalidArgument; input over a limit is ResourceExhausted, decided from
// the header before pixel memory is allocated. Messages say which limit and by how much.
Result<cv::Mat3b> DecodeImage(std::string_view bytes, const ImageLimits& limits);

// The probability map as an 8-bit grey PNG, pixel = round(255 * clamp(P, 0, 1)).
Result<std::string> EncodeProbabilityPng(const cv::Mat1f& probability);

}  // namespace tod::server
