// Reads an encoded image's pixel size from its header without decoding it, so a request can be
// refused for its size before any pixel memory is allocated (guard against decompression bombs).
#pragma once

#include <opencv2/core.hpp>
#include <string_view>

#include "core/base/status.h"

namespace tod::server {

enum class ImageFormat { kPng, kJpeg, kWebp };

struct ImageHeader {
  ImageFormat format = ImageFormat::kPng;
  cv::Size size;
};

// PNG (IHDR), baseline/progressive JPEG (first SOFn marker) and WebP (its RIFF container's first
// chunk, read by libwebp's header parser, which allocates nothing). Anything else, or a truncated
// header, is InvalidArgument with a message saying what was wrong.
Result<ImageHeader> PeekImageHeader(std::string_view bytes);

}  // namespace tod::server
