// The plain-PNG decoder against libpng (through cv::imdecode) on PNGs written here chunk by chunk,
// so that every filter type, split and odd chunk layout is covered, and on OpenCV's own PNGs; and
// its refusals, which must match the service's strict libpng decoder.
#include "core/data/plain_png.h"

#include <gtest/gtest.h>
#include <libdeflate.h>

#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/data/image_file.h"

namespace tod {
namespace {

// The PNG spec's Paeth predictor, written as the spec writes it (the decoder's form differs).
int SpecPaeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return a;
  if (pb <= pc) return b;
  return c;
}

std::string BigEndian(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
          static_cast<char>(v)};
}

std::string Chunk(const std::string& type, const std::string& data) {
  const std::string body = type + data;
  return BigEndian(static_cast<std::uint32_t>(data.size())) + body +
         BigEndian(libdeflate_crc32(0, body.data(), body.size()));
}

std::string Header(int width, int height, int depth, int colour, int interlace = 0) {
  return BigEndian(width) + BigEndian(height) + std::string{static_cast<char>(depth)} +
         std::string{static_cast<char>(colour)} + std::string{'\0', '\0'} +
         std::string{static_cast<char>(interlace)};
}

std::string Deflate(const std::string& raw) {
  libdeflate_compressor* c = libdeflate_alloc_compressor(6);
  std::string out(libdeflate_zlib_compress_bound(c, raw.size()), '\0');
  out.resize(libdeflate_zlib_compress(c, raw.data(), raw.size(), out.data(), out.size()));
  libdeflate_free_compressor(c);
  return out;
}

// A PNG of `image` (8-bit, 3 or 4 channels, RGB(A) order in the file) written chunk by chunk.
struct PngSpec {
  cv::Mat image;                   // CV_8UC3 or CV_8UC4, BGR(A) as OpenCV holds it
  std::vector<int> filters;        // per row, cycled; 0..4 (others make a corrupt file)
  int idat_chunks = 1;             // the compressed stream split into this many IDATs
  std::string before_data{};       // chunks between IHDR and the first IDAT
  std::string extra_raw{};         // appended to the filtered rows before compressing
  std::string extra_compressed{};  // appended to the zlib stream
};

std::string FilteredRows(const PngSpec& spec) {
  const int c = spec.image.channels();
  const std::size_t length = static_cast<std::size_t>(spec.image.cols) * c;
  std::vector<unsigned char> previous(length, 0), current(length);
  std::string raw;
  for (int y = 0; y < spec.image.rows; ++y) {
    const unsigned char* bgr = spec.image.ptr<unsigned char>(y);
    for (int x = 0; x < spec.image.cols; ++x)
      for (int k = 0; k < c; ++k) current[x * c + k] = bgr[x * c + (k < 3 ? 2 - k : k)];
    const int filter = spec.filters[static_cast<std::size_t>(y) % spec.filters.size()];
    raw.push_back(static_cast<char>(filter));
    for (std::size_t i = 0; i < length; ++i) {
      const int a = i >= static_cast<std::size_t>(c) ? current[i - c] : 0;
      const int b = previous[i];
      const int up_left = i >= static_cast<std::size_t>(c) ? previous[i - c] : 0;
      const int predicted = filter == 1   ? a
                            : filter == 2 ? b
                            : filter == 3 ? (a + b) / 2
                            : filter == 4 ? SpecPaeth(a, b, up_left)
                                          : 0;
      raw.push_back(static_cast<char>(current[i] - predicted));
    }
    previous = current;
  }
  return raw + spec.extra_raw;
}

std::string WritePng(const PngSpec& spec) {
  const std::string stream = Deflate(FilteredRows(spec)) + spec.extra_compressed;
  std::string png = std::string("\x89PNG\r\n\x1a\n", 8) +
                    Chunk("IHDR", Header(spec.image.cols, spec.image.rows, 8,
                                         spec.image.channels() == 3 ? 2 : 6)) +
                    spec.before_data;
  const std::size_t pieces = static_cast<std::size_t>(spec.idat_chunks);
  for (std::size_t p = 0; p < pieces; ++p) {
    png +=
        Chunk("IDAT", stream.substr(stream.size() * p / pieces,
                                    stream.size() * (p + 1) / pieces - stream.size() * p / pieces));
  }
  return png + Chunk("IEND", "");
}

cv::Mat NoiseImage(int rows, int cols, int channels, unsigned seed) {
  cv::Mat image(rows, cols, CV_8UC(channels));
  std::mt19937 rng(seed);
  for (int y = 0; y < rows; ++y)
    for (int i = 0; i < cols * channels; ++i)
      image.ptr<unsigned char>(y)[i] = static_cast<unsigned char>(rng() >> 24);
  // A smooth ramp on the top half, so the predictors see neighbours that agree as well.
  for (int y = 0; y < rows / 2; ++y)
    for (int i = 0; i < cols * channels; ++i)
      image.ptr<unsigned char>(y)[i] = static_cast<unsigned char>(3 * y + i / channels);
  return image;
}

cv::Mat LibpngDecode(const std::string& png) {
  return cv::imdecode(std::vector<unsigned char>(png.begin(), png.end()), cv::IMREAD_COLOR);
}

void ExpectSamePixels(const std::string& png, const std::string& what) {
  const cv::Mat reference = LibpngDecode(png);
  ASSERT_FALSE(reference.empty()) << what;
  ASSERT_TRUE(IsPlainPng(png)) << what;
  const Result<cv::Mat3b> decoded = DecodePlainPng(png, 1 << 20);
  ASSERT_TRUE(decoded.ok()) << what << ": " << decoded.status().message();
  ASSERT_EQ(decoded->size(), reference.size()) << what;
  EXPECT_EQ(cv::norm(*decoded, reference, cv::NORM_INF), 0) << what;
}

TEST(PlainPngTest, DecodesEveryFilterTypeLikeLibpng) {
  for (const int channels : {3, 4}) {
    for (const cv::Size size : {cv::Size(1, 1), cv::Size(5, 3), cv::Size(33, 17)}) {
      for (const std::vector<int>& filters :
           {std::vector<int>{0}, {1}, {2}, {3}, {4}, {4, 0, 3, 1, 2}}) {
        PngSpec spec{.image = NoiseImage(size.height, size.width, channels, 7), .filters = filters};
        ExpectSamePixels(WritePng(spec), std::to_string(channels) + " channels, " +
                                             std::to_string(size.width) + "x" +
                                             std::to_string(size.height) + ", filter " +
                                             std::to_string(filters.front()));
      }
    }
  }
}

// Wide rows are unfiltered in two halves on two threads (the right half one row behind the left);
// one thread unfilters whole rows, the reference. Every filter type, rows of odd and even widths,
// on 1, 2 and 3 threads: libpng's pixels each time.
TEST(PlainPngTest, RowHalvesOnTwoThreadsGiveThePixelsOfOne) {
  for (const int channels : {3, 4}) {
    for (const int width : {256, 601}) {
      PngSpec spec{.image = NoiseImage(23, width, channels, 5), .filters = {4, 1, 3, 2, 0, 4, 3}};
      const std::string png = WritePng(spec);
      for (const int threads : {1, 2, 3}) {
        cv::setNumThreads(threads);
        ExpectSamePixels(png, std::to_string(channels) + " channels, " + std::to_string(width) +
                                  " wide, " + std::to_string(threads) + " threads");
      }
    }
  }
  cv::setNumThreads(-1);
}

TEST(PlainPngTest, ReadsSplitDataAndSkipsAncillaryChunks) {
  PngSpec spec{.image = NoiseImage(20, 31, 3, 3), .filters = {4, 1, 2, 3, 0}, .idat_chunks = 7};
  spec.before_data = Chunk("gAMA", BigEndian(45455)) + Chunk("tEXt", std::string("a\0b", 3)) +
                     Chunk("PLTE", std::string(6, '\x10'));  // a suggested palette is allowed
  ExpectSamePixels(WritePng(spec), "7 IDATs after gAMA, tEXt and PLTE");
}

TEST(PlainPngTest, DecodesOpenCvsOwnPngsLikeLibpng) {
  for (const int channels : {3, 4}) {
    for (const int level : {0, 1, 6, 9}) {
      for (const int strategy : {cv::IMWRITE_PNG_STRATEGY_DEFAULT,
                                 cv::IMWRITE_PNG_STRATEGY_FILTERED, cv::IMWRITE_PNG_STRATEGY_RLE}) {
        std::vector<unsigned char> png;
        ASSERT_TRUE(
            cv::imencode(".png", NoiseImage(37, 61, channels, 11), png,
                         {cv::IMWRITE_PNG_COMPRESSION, level, cv::IMWRITE_PNG_STRATEGY, strategy}));
        ExpectSamePixels(std::string(png.begin(), png.end()),
                         "imencode level " + std::to_string(level));
      }
    }
  }
}

TEST(PlainPngTest, IsPlainPngLeavesOtherLayoutsToLibpng) {
  std::vector<unsigned char> grey, deep, jpeg;
  ASSERT_TRUE(cv::imencode(".png", cv::Mat1b(4, 4, 9), grey));
  ASSERT_TRUE(cv::imencode(".png", cv::Mat(4, 4, CV_16UC3, cv::Scalar::all(300)), deep));
  ASSERT_TRUE(cv::imencode(".jpg", cv::Mat3b(8, 8, cv::Vec3b(1, 2, 3)), jpeg));
  const std::string signature("\x89PNG\r\n\x1a\n", 8);
  EXPECT_FALSE(IsPlainPng(std::string(grey.begin(), grey.end())));
  EXPECT_FALSE(IsPlainPng(std::string(deep.begin(), deep.end())));
  EXPECT_FALSE(IsPlainPng(std::string(jpeg.begin(), jpeg.end())));
  EXPECT_FALSE(IsPlainPng(signature + Chunk("IHDR", Header(4, 4, 8, 3))));     // palette
  EXPECT_FALSE(IsPlainPng(signature + Chunk("IHDR", Header(4, 4, 8, 2, 1))));  // interlaced
  EXPECT_TRUE(IsPlainPng(signature + Chunk("IHDR", Header(4, 4, 8, 2))));
  EXPECT_FALSE(IsPlainPng((signature + Chunk("IHDR", Header(4, 4, 8, 2))).substr(0, 28)));
  EXPECT_FALSE(DecodePlainPng(std::string(grey.begin(), grey.end()), 1 << 20).ok());
}

// Every corrupt file is InvalidArgument with a message, never a crash or a partial image.
void ExpectRefused(const std::string& png, const std::string& what) {
  const Result<cv::Mat3b> decoded = DecodePlainPng(png, 1 << 20);
  ASSERT_FALSE(decoded.ok()) << what;
  EXPECT_EQ(decoded.status().code(), StatusCode::kInvalidArgument) << what;
  EXPECT_FALSE(decoded.status().message().empty()) << what;
}

TEST(PlainPngTest, RefusesWhatTheStrictLibpngDecoderRefuses) {
  const PngSpec good{.image = NoiseImage(9, 11, 3, 5), .filters = {4, 1}, .idat_chunks = 2};
  const std::string png = WritePng(good);
  ASSERT_TRUE(DecodePlainPng(png, 1 << 20).ok());
  for (std::size_t cut = 0; cut < png.size(); ++cut) {
    ExpectRefused(png.substr(0, cut), "cut at " + std::to_string(cut));
  }
  std::string bad_crc = png;
  bad_crc[50] ^= 1;  // inside the first IDAT's data
  ExpectRefused(bad_crc, "CRC mismatch");
  PngSpec bad_filter = good;
  bad_filter.filters = {5};
  ExpectRefused(WritePng(bad_filter), "filter type 5");
  PngSpec too_much = good;
  too_much.extra_raw = std::string(34, '\0');  // one more row
  ExpectRefused(WritePng(too_much), "an extra row");
  PngSpec trailing = good;
  trailing.extra_compressed = "xyz";
  ExpectRefused(WritePng(trailing), "bytes after the zlib stream");
  const std::string iend = Chunk("IEND", "");
  const std::string without_iend = png.substr(0, png.size() - iend.size());
  ExpectRefused(without_iend, "no IEND");
  ExpectRefused(without_iend + Chunk("ABCD", "x") + iend, "unknown critical chunk");
  ExpectRefused(without_iend + Chunk("tEXt", "k") + Chunk("IDAT", "") + iend, "IDATs not one run");
  ExpectRefused(Chunk("IHDR", Header(4, 4, 8, 2)) + png.substr(8), "IHDR before the signature");
  // The zlib stream's last byte (of its Adler-32) flipped, the chunk's CRC made right again, so
  // that only the zlib checksum is wrong.
  std::string bad_adler = png;
  const std::size_t type_at = bad_adler.rfind("IDAT");
  const auto* length_bytes = reinterpret_cast<const unsigned char*>(bad_adler.data() + type_at - 4);
  const std::size_t length = (std::size_t{length_bytes[0]} << 24) |
                             (std::size_t{length_bytes[1]} << 16) |
                             (std::size_t{length_bytes[2]} << 8) | length_bytes[3];
  bad_adler[type_at + 4 + length - 1] ^= 0x40;
  bad_adler.replace(type_at + 4 + length, 4,
                    BigEndian(libdeflate_crc32(0, bad_adler.data() + type_at, 4 + length)));
  ExpectRefused(bad_adler, "Adler-32 mismatch");
}

TEST(PlainPngTest, ChecksThePixelLimitBeforeAnyPixelMemory) {
  const std::string png = WritePng({.image = NoiseImage(32, 64, 3, 1), .filters = {0}});
  EXPECT_EQ(DecodePlainPng(png, 64 * 32 - 1).status().code(), StatusCode::kResourceExhausted);
  EXPECT_TRUE(DecodePlainPng(png, 64 * 32).ok());
  // A 30000 x 30000 header over a few bytes of data: refused as too little data for the size,
  // before a 2.7 GB buffer is allocated.
  const std::string signature("\x89PNG\r\n\x1a\n", 8);
  const std::string huge = signature + Chunk("IHDR", Header(30000, 30000, 8, 2)) +
                           Chunk("IDAT", Deflate(std::string(100, '\0'))) + Chunk("IEND", "");
  const Result<cv::Mat3b> decoded = DecodePlainPng(huge, 1LL << 40);
  ASSERT_FALSE(decoded.ok());
  EXPECT_EQ(decoded.status().code(), StatusCode::kInvalidArgument);
}

TEST(DecodeColourImageTest, PlainPngsAndOtherFormatsGiveLibpngsPixels) {
  std::vector<unsigned char> rgb, grey;
  const cv::Mat noise = NoiseImage(12, 14, 3, 2);
  ASSERT_TRUE(cv::imencode(".png", noise, rgb));
  ASSERT_TRUE(cv::imencode(".png", cv::Mat1b(5, 6, 77), grey));
  const Result<cv::Mat3b> from_rgb = DecodeColourImage(std::string(rgb.begin(), rgb.end()));
  ASSERT_TRUE(from_rgb.ok());
  EXPECT_EQ(cv::norm(*from_rgb, noise, cv::NORM_INF), 0);
  const Result<cv::Mat3b> from_grey = DecodeColourImage(std::string(grey.begin(), grey.end()));
  ASSERT_TRUE(from_grey.ok());
  EXPECT_EQ(cv::norm(*from_grey, cv::Mat3b(5, 6, cv::Vec3b(77, 77, 77)), cv::NORM_INF), 0);
  EXPECT_EQ(DecodeColourImage("not an image").status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace tod
