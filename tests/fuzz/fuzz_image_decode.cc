// Fuzzes what the service does with the bytes of an uploaded image: the header sniffer that
// admission uses (PeekImageHeader) and the strict JPEG/PNG/WebP decoders behind DecodeImage.
// Invariants checked besides memory safety: a decoded image is never larger than the pixel limit,
// never larger than its own header said, and decoding is refused exactly when it should be.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <string_view>

#include "core/data/plain_png.h"
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
  const tod::Result<tod::server::ImageHeader> header = tod::server::PeekImageHeader(bytes);
  if (header.ok()) Check(header->size.width > 0 && header->size.height > 0);

  const tod::server::ImageLimits limits{.max_bytes = 1 << 20, .max_pixels = kMaxPixels};
  const tod::Result<cv::Mat3b> image = tod::server::DecodeImage(bytes, limits);
  if (image.ok()) {
    Check(header.ok());  // DecodeImage sniffs first: no header, no image
    Check(!image->empty() && image->total() <= static_cast<size_t>(kMaxPixels));
    Check(image->size() == header->size);
  } else {
    Check(!image.status().message().empty());
  }

  // The plain-PNG decoder agrees with libpng: whatever it accepts, libpng (lenient, through
  // OpenCV) decodes to the same pixels. It may refuse more (it is strict); never less.
  const tod::Result<cv::Mat3b> plain = tod::DecodePlainPng(bytes, kMaxPixels);
  if (plain.ok()) {
    Check(tod::IsPlainPng(bytes) && !plain->empty() &&
          plain->total() <= static_cast<size_t>(kMaxPixels));
    const cv::Mat reference = cv::imdecode(
        cv::Mat(1, static_cast<int>(size), CV_8U, const_cast<uint8_t*>(data)), cv::IMREAD_COLOR);
    Check(!reference.empty() && reference.size() == plain->size() &&
          cv::norm(reference, *plain, cv::NORM_INF) == 0);
  }

  // The decoders are also called directly (DecodeImage only reaches the one the header names),
  // so a PNG decoder is fuzzed with JPEG bytes and the other way round.
  for (const auto decode : {&tod::server::DecodeJpegStrict, &tod::server::DecodePngStrict,
                            &tod::server::DecodeWebpStrict}) {
    const tod::Result<cv::Mat3b> direct = decode(bytes, kMaxPixels);
    if (direct.ok()) Check(!direct->empty() && direct->total() <= static_cast<size_t>(kMaxPixels));
  }
  return 0;
}
