#include "core/data/plain_png.h"

#include <libdeflate.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <string>
#include <vector>

namespace tod {
namespace {

constexpr std::string_view kSignature("\x89PNG\r\n\x1a\n", 8);
constexpr std::size_t kChunkOverhead = 12;  // length, type, CRC
constexpr std::uint32_t kMaxChunkLength = 0x7fffffffu;
// DEFLATE cannot expand its input more than ~1032 times: a stream whose image would need more
// is refused before the image buffer is allocated.
constexpr std::uint64_t kMaxInflateRatio = 1032;

struct PlainLayout {
  int width = 0;
  int height = 0;
  int channels = 0;  // 3 (RGB) or 4 (RGBA)
};

// What the chunk walk keeps: the header's fields and the image data, still compressed (one view
// per IDAT chunk, in order).
struct PngChunks {
  std::string_view header;
  std::vector<std::string_view> image_data;
};

std::uint32_t BigEndian32(const char* p) {
  const auto* b = reinterpret_cast<const unsigned char*>(p);
  return (std::uint32_t{b[0]} << 24) | (std::uint32_t{b[1]} << 16) | (std::uint32_t{b[2]} << 8) |
         std::uint32_t{b[3]};
}

Status Corrupt(const std::string& why) {
  return Status::InvalidArgument("image: cannot decode PNG (corrupt or truncated): " + why);
}

bool IsLetter(char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }

// Bit 5 of the first letter clear: the chunk is critical, and a decoder that does not know it
// must not go on (PNG spec 5.4).
bool IsCritical(std::string_view type) { return (type[0] & 0x20) == 0; }

Result<PlainLayout> ParseHeader(std::string_view ihdr) {
  if (ihdr.size() != 13) return Corrupt("IHDR is not 13 bytes");
  const std::uint32_t width = BigEndian32(ihdr.data());
  const std::uint32_t height = BigEndian32(ihdr.data() + 4);
  if (width == 0 || height == 0 || width > kMaxChunkLength || height > kMaxChunkLength) {
    return Corrupt("image size out of range");
  }
  const auto depth = static_cast<unsigned char>(ihdr[8]);
  const auto colour = static_cast<unsigned char>(ihdr[9]);
  const bool standard = ihdr[10] == 0 && ihdr[11] == 0;  // deflate, adaptive filtering
  const bool interlaced = ihdr[12] != 0;
  if (depth != 8 || (colour != 2 && colour != 6) || !standard || interlaced) {
    return Status::InvalidArgument("image: not a plain PNG (8-bit RGB or RGBA, not interlaced)");
  }
  return PlainLayout{static_cast<int>(width), static_cast<int>(height), colour == 2 ? 3 : 4};
}

// Walks the chunks from the signature to IEND, checking each CRC and the order the PNG spec
// demands of the chunks that matter here (IHDR first, the IDATs one run, IEND last). Ancillary
// chunks are skipped; bytes after IEND are ignored, as libpng ignores them.
Result<PngChunks> WalkChunks(std::string_view bytes) {
  if (bytes.substr(0, kSignature.size()) != kSignature) return Corrupt("no PNG signature");
  PngChunks chunks;
  bool data_ended = false;
  std::size_t at = kSignature.size();
  for (;;) {
    if (bytes.size() - at < kChunkOverhead) return Corrupt("unexpected end of data before IEND");
    const std::uint32_t length = BigEndian32(bytes.data() + at);
    if (length > kMaxChunkLength || length > bytes.size() - at - kChunkOverhead) {
      return Corrupt("chunk length past the end of the data");
    }
    const std::string_view type = bytes.substr(at + 4, 4);
    const std::string_view data = bytes.substr(at + 8, length);
    const std::uint32_t stored_crc = BigEndian32(bytes.data() + at + 8 + length);
    if (!IsLetter(type[0]) || !IsLetter(type[1]) || !IsLetter(type[2]) || !IsLetter(type[3])) {
      return Corrupt("invalid chunk type");
    }
    if (libdeflate_crc32(0, bytes.data() + at + 4, 4 + length) != stored_crc) {
      return Corrupt("CRC error in chunk " + std::string(type));
    }
    at += kChunkOverhead + length;
    const bool first = chunks.header.data() == nullptr;
    if (first != (type == "IHDR")) return Corrupt("IHDR is not the first chunk, or not the only");
    if (type == "IHDR") {
      chunks.header = data;
    } else if (type == "IDAT") {
      if (data_ended) return Corrupt("IDAT chunks are not consecutive");
      chunks.image_data.push_back(data);
    } else if (type == "IEND") {
      if (chunks.image_data.empty()) return Corrupt("no image data");
      return chunks;
    } else {
      data_ended = !chunks.image_data.empty();
      if (type != "PLTE" && IsCritical(type)) {
        return Corrupt("unknown critical chunk " + std::string(type));
      }
    }
  }
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// The filtered rows, inflated: one filter byte and the pixel bytes of each row, back to back.
struct FilteredRows {
  std::unique_ptr<unsigned char[]> bytes;
  std::size_t size = 0;
};

// Inflates the IDAT stream, which must fill exactly `size` bytes with the zlib stream ending
// exactly at the end of the data. A stream too short to expand to `size` is refused before the
// buffer exists.
Result<FilteredRows> Inflate(const std::vector<std::string_view>& image_data, std::size_t size) {
  std::size_t compressed = 0;
  for (const std::string_view part : image_data) compressed += part.size();
  if (size / kMaxInflateRatio > compressed) return Corrupt("not enough image data");
  std::string joined;
  std::string_view stream = image_data.front();
  if (image_data.size() > 1) {
    joined.reserve(compressed);
    for (const std::string_view part : image_data) joined.append(part);
    stream = joined;
  }
  const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> decompressor(
      libdeflate_alloc_decompressor());
  if (!decompressor) return Status::Internal("image: cannot allocate a PNG inflater");
  FilteredRows rows{std::make_unique_for_overwrite<unsigned char[]>(size), size};
  std::size_t read = 0, written = 0;
  const libdeflate_result result = libdeflate_zlib_decompress_ex(
      decompressor.get(), stream.data(), stream.size(), rows.bytes.get(), size, &read, &written);
  if (result == LIBDEFLATE_INSUFFICIENT_SPACE) return Corrupt("too much image data");
  if (result != LIBDEFLATE_SUCCESS) return Corrupt("invalid zlib stream in IDAT");
  if (written != size) return Corrupt("not enough image data");
  if (read != stream.size()) return Corrupt("extra compressed data after the image");
  return rows;
}

int PaethPredictor(int left, int up, int up_left) {
  const int to_left = std::abs(up - up_left);  // |p - left| with p = left + up - up_left
  const int to_up = std::abs(left - up_left);  // |p - up|
  const int to_corner = std::abs(left + up - 2 * up_left);  // |p - up_left|
  const int nearer = to_up < to_left ? up : left;
  const int nearer_distance = to_up < to_left ? to_up : to_left;
  return to_corner < nearer_distance ? up_left : nearer;
}

// Undoes one row's filter in place (PNG spec 9.2) on bytes [begin, end) of the row; `begin` is a
// whole number of pixels, and bytes before it are already unfiltered. `previous` is the row above,
// already unfiltered (zeros for the first row); C bytes a pixel. The byte arithmetic is modulo 256.
template <int C>
void UnfilterSpan(unsigned char filter, unsigned char* row, const unsigned char* previous,
                  std::size_t begin, std::size_t end) {
  switch (filter) {
    case 0:
      return;
    case 1:
      for (std::size_t i = std::max<std::size_t>(begin, C); i < end; ++i)
        row[i] = static_cast<unsigned char>(row[i] + row[i - C]);
      return;
    case 2:
      for (std::size_t i = begin; i < end; ++i)
        row[i] = static_cast<unsigned char>(row[i] + previous[i]);
      return;
    case 3:
      for (std::size_t i = begin; i < std::min<std::size_t>(end, C); ++i)
        row[i] = static_cast<unsigned char>(row[i] + (previous[i] >> 1));
      for (std::size_t i = std::max<std::size_t>(begin, C); i < end; ++i) {
        row[i] = static_cast<unsigned char>(row[i] + ((row[i - C] + previous[i]) >> 1));
      }
      return;
    case 4: {
      // The left and upper-left bytes of each channel stay in registers: read back from memory,
      // every byte waited for the store of the one before (the row is one dependency chain).
      int left[C] = {}, up_left[C] = {};
      if (begin >= C) {
        for (int k = 0; k < C; ++k)
          left[k] = row[begin - C + k], up_left[k] = previous[begin - C + k];
      }
      for (std::size_t i = begin; i < end; i += C) {
        for (int k = 0; k < C; ++k) {
          const int up = previous[i + k];
          left[k] =
              static_cast<unsigned char>(row[i + k] + PaethPredictor(left[k], up, up_left[k]));
          row[i + k] = static_cast<unsigned char>(left[k]);
          up_left[k] = up;
        }
      }
      return;
    }
    default:
      return;  // filter types were checked before any row (UnfilterToBgr)
  }
}

// Pixels [first, last) of one unfiltered row (after its filter byte), reordered to BGR.
template <int C>
void CopyToBgr(const unsigned char* pixels, int first, int last, cv::Vec3b* out) {
  for (int x = first; x < last; ++x) {
    const unsigned char* pixel = pixels + static_cast<std::size_t>(x) * C;
    out[x] = cv::Vec3b(pixel[2], pixel[1], pixel[0]);
  }
}

// Columns [first, last) of every row: unfiltered in place and written into `image`, top to
// bottom. When first > 0, the columns left of `first` of row y must be final before row y is
// done here: `left_rows` (if any) counts the rows whose left part is final, and is waited on.
// `done_rows` (if any) is raised after each row.
template <int C>
void UnfilterColumns(FilteredRows& raw, cv::Mat3b& image, int first, int last,
                     const std::atomic<int>* left_rows, std::atomic<int>* done_rows) {
  const std::size_t length = static_cast<std::size_t>(image.cols) * C;
  const std::vector<unsigned char> zeros(length, 0);
  const unsigned char* previous = zeros.data();
  for (int y = 0; y < image.rows; ++y) {
    if (left_rows != nullptr) {
      for (int ready = left_rows->load(std::memory_order_acquire); ready <= y;
           ready = left_rows->load(std::memory_order_acquire))
        left_rows->wait(ready, std::memory_order_acquire);
    }
    unsigned char* row = raw.bytes.get() + static_cast<std::size_t>(y) * (length + 1);
    UnfilterSpan<C>(row[0], row + 1, previous, static_cast<std::size_t>(first) * C,
                    static_cast<std::size_t>(last) * C);
    CopyToBgr<C>(row + 1, first, last, image[y]);
    previous = row + 1;
    if (done_rows != nullptr) {
      done_rows->store(y + 1, std::memory_order_release);
      done_rows->notify_one();
    }
  }
}

// Unfilters every row of `raw` in place and writes its pixels, reordered to BGR, into `image`.
// With two threads or more (OpenCV's pool, the request's threads) the rows are cut into a left
// and a right half, each on a thread: a row's right half needs its left half (the left neighbour
// of its first pixel) and the row above, its left half only the row above, so the right half
// follows the left one row behind. One thread unfilters whole rows (the reference); the bytes are
// the same either way.
template <int C>
Status UnfilterToBgr(FilteredRows& raw, cv::Mat3b& image) {
  const std::size_t stride = static_cast<std::size_t>(image.cols) * C + 1;
  for (int y = 0; y < image.rows; ++y)
    if (raw.bytes[static_cast<std::size_t>(y) * stride] > 4) return Corrupt("bad filter type");
  constexpr int kMinSplitColumns = 256;
  if (cv::getNumThreads() < 2 || image.cols < kMinSplitColumns) {
    UnfilterColumns<C>(raw, image, 0, image.cols, nullptr, nullptr);
    return Status::Ok();
  }
  const int middle = image.cols / 2;
  std::atomic<int> left_rows{0};
  std::atomic<int> started{0};
  // A task takes its half when it starts, so the left half belongs to the task that started
  // first: the right half never waits for a task that has not begun, however the pool runs them.
  cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& range) {
    for (int n = range.start; n < range.end; ++n) {
      if (started.fetch_add(1) == 0)
        UnfilterColumns<C>(raw, image, 0, middle, nullptr, &left_rows);
      else
        UnfilterColumns<C>(raw, image, middle, image.cols, &left_rows, nullptr);
    }
  });
  return Status::Ok();
}

}  // namespace

bool IsPlainPng(std::string_view bytes) {
  constexpr std::size_t kHeaderEnd = 8 + 8 + 13;  // signature, IHDR length and type, its data
  if (bytes.size() < kHeaderEnd || bytes.substr(0, 8) != kSignature) return false;
  if (BigEndian32(bytes.data() + 8) != 13 || bytes.substr(12, 4) != "IHDR") return false;
  return ParseHeader(bytes.substr(16, 13)).ok();
}

Result<cv::Mat3b> DecodePlainPng(std::string_view bytes, long long max_pixels) {
  Result<PngChunks> chunks = WalkChunks(bytes);
  if (!chunks.ok()) return chunks.status();
  const Result<PlainLayout> layout = ParseHeader(chunks->header);
  if (!layout.ok()) return layout.status();
  const long long pixels = static_cast<long long>(layout->width) * layout->height;
  if (pixels > max_pixels) {
    return Status::ResourceExhausted("image: PNG " + std::to_string(layout->width) + "x" +
                                     std::to_string(layout->height) + " = " +
                                     std::to_string(pixels) + " pixels is over the limit of " +
                                     std::to_string(max_pixels) + " pixels");
  }
  Result<FilteredRows> raw = Inflate(
      chunks->image_data, static_cast<std::size_t>(layout->height) *
                              (1 + static_cast<std::size_t>(layout->width) * layout->channels));
  if (!raw.ok()) return raw.status();
  cv::Mat3b image(layout->height, layout->width);
  const Status unfiltered =
      layout->channels == 3 ? UnfilterToBgr<3>(*raw, image) : UnfilterToBgr<4>(*raw, image);
  if (!unfiltered.ok()) return unfiltered;
  return image;
}

}  // namespace tod
