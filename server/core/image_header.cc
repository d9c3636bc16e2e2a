#include "server/core/image_header.h"

#include <webp/decode.h>

#include <array>
#include <cstdint>
#include <string>

namespace tod::server {
namespace {

uint32_t BigEndian32(std::string_view b, size_t at) {
  return (static_cast<uint32_t>(static_cast<uint8_t>(b[at])) << 24) |
         (static_cast<uint32_t>(static_cast<uint8_t>(b[at + 1])) << 16) |
         (static_cast<uint32_t>(static_cast<uint8_t>(b[at + 2])) << 8) |
         static_cast<uint32_t>(static_cast<uint8_t>(b[at + 3]));
}

uint32_t BigEndian16(std::string_view b, size_t at) {
  return (static_cast<uint32_t>(static_cast<uint8_t>(b[at])) << 8) |
         static_cast<uint32_t>(static_cast<uint8_t>(b[at + 1]));
}

constexpr std::array<uint8_t, 8> kPngSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

bool StartsWithPngSignature(std::string_view b) {
  if (b.size() < kPngSignature.size()) return false;
  for (size_t i = 0; i < kPngSignature.size(); ++i) {
    if (static_cast<uint8_t>(b[i]) != kPngSignature[i]) return false;
  }
  return true;
}

Result<ImageHeader> PeekPng(std::string_view b) {
  // Signature (8) + chunk length (4) + "IHDR" (4) + width (4) + height (4).
  if (b.size() < 24 || b.substr(12, 4) != "IHDR") {
    return Status::InvalidArgument("image: PNG is truncated before its IHDR header");
  }
  const uint32_t width = BigEndian32(b, 16);
  const uint32_t height = BigEndian32(b, 20);
  if (width == 0 || height == 0 || width > (1u << 31) - 1 || height > (1u << 31) - 1) {
    return Status::InvalidArgument("image: PNG header has an invalid size " +
                                   std::to_string(width) + "x" + std::to_string(height));
  }
  return ImageHeader{ImageFormat::kPng,
                     cv::Size(static_cast<int>(width), static_cast<int>(height))};
}

// Walks the JPEG marker segments up to the first start-of-frame marker, which holds the size.
Result<ImageHeader> PeekJpeg(std::string_view b) {
  size_t at = 2;  // after SOI
  while (at + 4 <= b.size()) {
    if (static_cast<uint8_t>(b[at]) != 0xFF) {
      return Status::InvalidArgument("image: JPEG marker expected at byte " + std::to_string(at));
    }
    const uint8_t marker = static_cast<uint8_t>(b[at + 1]);
    if (marker == 0xFF) {  // fill byte
      ++at;
      continue;
    }
    if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {
      at += 2;  // markers without a length field
      continue;
    }
    const uint32_t length = BigEndian16(b, at + 2);
    if (length < 2) return Status::InvalidArgument("image: JPEG segment with invalid length");
    // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC).
    const bool is_sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (is_sof) {
      if (at + 9 > b.size()) break;
      const uint32_t height = BigEndian16(b, at + 5);
      const uint32_t width = BigEndian16(b, at + 7);
      if (width == 0 || height == 0) {
        return Status::InvalidArgument("image: JPEG header has an invalid size " +
                                       std::to_string(width) + "x" + std::to_string(height));
      }
      return ImageHeader{ImageFormat::kJpeg,
                         cv::Size(static_cast<int>(width), static_cast<int>(height))};
    }
    if (marker == 0xDA || marker == 0xD9) break;  // scan data / end before any frame header
    at += 2 + length;
  }
  return Status::InvalidArgument("image: JPEG has no frame header (truncated or corrupt)");
}

// "RIFF" <size> "WEBP": a WebP file (the first chunk then says lossy, lossless or extended).
bool StartsWithWebpSignature(std::string_view b) {
  return b.size() >= 12 && b.substr(0, 4) == "RIFF" && b.substr(8, 4) == "WEBP";
}

Result<ImageHeader> PeekWebp(std::string_view b) {
  int width = 0, height = 0;
  if (!WebPGetInfo(reinterpret_cast<const uint8_t*>(b.data()), b.size(), &width, &height) ||
      width <= 0 || height <= 0) {
    return Status::InvalidArgument("image: WebP header is truncated or invalid");
  }
  return ImageHeader{ImageFormat::kWebp, cv::Size(width, height)};
}

}  // namespace

Result<ImageHeader> PeekImageHeader(std::string_view bytes) {
  if (bytes.empty()) {
    return Status::InvalidArgument("image: empty body, expected a JPEG, PNG or WebP");
  }
  if (StartsWithPngSignature(bytes)) return PeekPng(bytes);
  if (StartsWithWebpSignature(bytes)) return PeekWebp(bytes);
  if (bytes.size() >= 3 && static_cast<uint8_t>(bytes[0]) == 0xFF &&
      static_cast<uint8_t>(bytes[1]) == 0xD8 && static_cast<uint8_t>(bytes[2]) == 0xFF) {
    return PeekJpeg(bytes);
  }
  return Status::InvalidArgument("image: not a JPEG, PNG or WebP (unrecognised signature, " +
                                 std::to_string(bytes.size()) + " bytes)");
}

}  // namespace tod::server
