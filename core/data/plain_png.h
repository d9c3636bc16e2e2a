// PNG decoding for the frames cameras and datasets send in practice: 8-bit RGB or RGBA, not
// interlaced ("plain" PNGs). libpng takes ~48 ms for a 2048 x 1024 Lost and Found frame, a
// tenth of the whole detection on one core and the largest step no second thread can share:
// about 20 ms is zlib's inflate, most of the rest libpng's generic row filters. Whole-buffer
// inflate (libdeflate) and row filters specialised to 3 and 4 bytes a pixel take ~20 ms for the
// same pixels (the tests hold it to libpng, byte for byte). Every other PNG (palette, grey,
// 16-bit, interlaced) stays with libpng: IsPlainPng says which decoder a file needs.
#pragma once

#include <opencv2/core.hpp>
#include <string_view>

#include "core/base/status.h"

namespace tod {

// True when `bytes` begin with the PNG signature and an IHDR of an 8-bit RGB or RGBA image
// without interlacing. Reads the first 33 bytes only; says nothing about the rest.
bool IsPlainPng(std::string_view bytes);

// Decodes a plain PNG to 8-bit BGR (alpha dropped, as libpng's strip_alpha does). Strict, like
// the service's libpng decoder: a bad chunk CRC, chunk order or zlib stream (with its Adler-32),
// too little or too much image data, an unknown critical chunk or a missing IEND is
// InvalidArgument; a header over `max_pixels` is ResourceExhausted, before any pixel memory
// exists. A PNG that is not plain is InvalidArgument.
Result<cv::Mat3b> DecodePlainPng(std::string_view bytes, long long max_pixels);

}  // namespace tod
