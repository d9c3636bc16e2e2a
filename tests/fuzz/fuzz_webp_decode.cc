// Fuzzes the strict WebP decoder behind DecodeImage (REST image/webp, gRPC frames in WebP): the
// header peek admission uses and libwebp's decoder, on lossy (VP8), lossless (VP8L) and extended
// (VP8X, alpha) seeds. Invariants besides memory safety: a decoded frame is exactly the size its
// header names, never over the pixel limit, and a refusal always says why.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "server/core/image_codec.h"
#include "server/core/image_header.h"
#include "server/core/strict_decoders.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

// Far below the service's 4 M default so that each run stays fast; the limit logic is the same.
constexpr long long kMaxPixels = 1 << 18;

using tod::fuzz::Check;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const tod::Result<cv::Mat3b> direct = tod::server::DecodeWebpStrict(bytes, kMaxPixels);
  if (direct.ok()) {
    Check(!direct->empty() && direct->total() <= static_cast<size_t>(kMaxPixels));
  } else {
    Check(!direct.status().message().empty());
  }
  const tod::Result<tod::server::ImageHeader> header = tod::server::PeekImageHeader(bytes);
  const tod::server::ImageLimits limits{.max_bytes = 1 << 20, .max_pixels = kMaxPixels};
  const tod::Result<cv::Mat3b> image = tod::server::DecodeImage(bytes, limits);
  if (image.ok() && header.ok() && header->format == tod::server::ImageFormat::kWebp) {
    Check(image->size() == header->size);  // the peeked size is the decoded size
    Check(direct.ok() && direct->size() == image->size());
  }
  return 0;
}
