// JPEG, PNG and WebP decoders that refuse what OpenCV's imdecode would silently patch up. libjpeg
// reports truncated or corrupt entropy data only as warnings ("Premature end of JPEG file",
// "Corrupt JPEG data: ...") and fills the missing pixels with grey; libpng downgrades several
// data errors to warnings too. libwebp is strict by itself once told it has all the data (a
// truncated file is an error, not a partly grey frame). Here every warning is an error, the pixel
// limit is checked on the decoder's own header before any pixel memory exists, and nothing is
// printed to stderr.
#pragma once

#include <opencv2/core.hpp>
#include <string_view>

#include "core/base/status.h"

namespace tod::server {

// 8-bit BGR. Errors: InvalidArgument (corrupt, truncated, unsupported), ResourceExhausted (the
// header's width * height is over `max_pixels`).
Result<cv::Mat3b> DecodeJpegStrict(std::string_view bytes, long long max_pixels);
Result<cv::Mat3b> DecodePngStrict(std::string_view bytes, long long max_pixels);
// Still WebP, lossy (VP8) or lossless (VP8L), with or without alpha (dropped); animated WebP is
// refused.
Result<cv::Mat3b> DecodeWebpStrict(std::string_view bytes, long long max_pixels);

}  // namespace tod::server
