// Reading one image file for a dataset reader, with errors that tell a missing file from one that
// exists but does not decode.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "core/base/status.h"

namespace tod {

// The pixels OpenCV's decoders accept (its CV_IO_MAX_IMAGE_PIXELS default): the bound for frames
// read from files the user named, which are not hostile as a request's bytes are.
inline constexpr long long kMaxFilePixels = 1LL << 30;

// A file's bytes. NotFound when it cannot be opened, DataLoss when reading fails.
Result<std::string> ReadFileBytes(const std::string& path);

// A frame's encoded bytes to 8-bit BGR, decoded as tod_server decodes them where that is fast:
// plain PNGs (8-bit RGB/RGBA) by DecodePlainPng, every other format by cv::imdecode.
// InvalidArgument when the bytes do not decode.
Result<cv::Mat3b> DecodeColourImage(std::string_view bytes);

// cv::imread(path, flags), colour frames (flags == cv::IMREAD_COLOR) by DecodeColourImage; NotFound
// when there is no such file, DataLoss when it does not decode. `what` names the file's role in
// messages ("image", "instanceIds", "mask").
Result<cv::Mat> ReadImageFile(const std::string& path, int flags, const std::string& what);

}  // namespace tod
