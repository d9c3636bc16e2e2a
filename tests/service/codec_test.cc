// Image header peeking and decoding limits.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "server/core/image_codec.h"
#include "server/core/image_header.h"
#include "server/core/strict_decoders.h"
#include "tests/service/test_images.h"

namespace tod::server {
namespace {

TEST(ImageHeaderTest, ReadsPngAndJpegSizesWithoutDecoding) {
  const cv::Mat3b frame = testing::RoadFrame(321, 123);
  const Result<ImageHeader> png = PeekImageHeader(testing::Encode(frame, ".png"));
  ASSERT_TRUE(png.ok()) << png.status().message();
  EXPECT_EQ(png->format, ImageFormat::kPng);
  EXPECT_EQ(png->size, cv::Size(321, 123));
  const Result<ImageHeader> jpeg = PeekImageHeader(testing::Encode(frame, ".jpg"));
  ASSERT_TRUE(jpeg.ok()) << jpeg.status().message();
  EXPECT_EQ(jpeg->format, ImageFormat::kJpeg);
  EXPECT_EQ(jpeg->size, cv::Size(321, 123));
}

TEST(ImageHeaderTest, ReadsHandWrittenPngHeader) {
  // Signature, IHDR length 13, "IHDR", width 0x00010002 = 65538, height 7.
  const std::string header("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\x01\0\x02\0\0\0\x07", 24);
  const Result<ImageHeader> png = PeekImageHeader(header);
  ASSERT_TRUE(png.ok()) << png.status().message();
  EXPECT_EQ(png->size, cv::Size(65538, 7));
}

TEST(ImageHeaderTest, RejectsEmptyUnknownAndTruncated) {
  EXPECT_EQ(PeekImageHeader("").status().code(), StatusCode::kInvalidArgument);
  const Status garbage = PeekImageHeader("GIF89a....").status();
  EXPECT_EQ(garbage.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(garbage.message().find("not a JPEG, PNG or WebP"), std::string::npos);
  const std::string png = testing::RoadPng();
  EXPECT_FALSE(PeekImageHeader(png.substr(0, 20)).ok());
  const std::string jpeg = testing::Encode(testing::RoadFrame(), ".jpg");
  EXPECT_FALSE(PeekImageHeader(jpeg.substr(0, 4)).ok());
}

TEST(ImageCodecTest, DecodesWithinLimitsAndRefusesOverLimits) {
  const std::string png = testing::RoadPng(320, 160);
  ImageLimits limits;
  limits.max_pixels = 320 * 160;
  const Result<cv::Mat3b> decoded = DecodeImage(png, limits);
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  EXPECT_EQ(decoded->size(), cv::Size(320, 160));
  EXPECT_EQ((*decoded)(5, 5), cv::Vec3b(200, 170, 120));  // PNG is lossless

  limits.max_pixels = 320 * 160 - 1;
  const Status too_many = DecodeImage(png, limits).status();
  EXPECT_EQ(too_many.code(), StatusCode::kResourceExhausted);
  EXPECT_NE(too_many.message().find("51200 pixels"), std::string::npos) << too_many.message();

  limits = ImageLimits{};
  limits.max_bytes = png.size() - 1;
  EXPECT_EQ(DecodeImage(png, limits).status().code(), StatusCode::kResourceExhausted);
}

TEST(ImageCodecTest, GreyPngBecomesBgr) {
  const cv::Mat1b grey(10, 12, uchar{77});
  const Result<cv::Mat3b> decoded = DecodeImage(testing::Encode(grey, ".png"), ImageLimits{});
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ((*decoded)(3, 4), cv::Vec3b(77, 77, 77));
}

// A frame with texture, so that its JPEG has substantial entropy-coded data.
cv::Mat3b Textured(int width, int height) {
  cv::Mat3b frame(height, width);
  cv::RNG rng(11);
  rng.fill(frame, cv::RNG::UNIFORM, 0, 255);
  return frame;
}

TEST(StrictDecoderTest, DecodesJpegAndPngLikeOpenCv) {
  const cv::Mat3b frame = Textured(97, 41);
  for (const std::string ext : {".jpg", ".png"}) {
    const std::string bytes = testing::Encode(frame, ext);
    const Result<cv::Mat3b> ours = DecodeImage(bytes, ImageLimits{});
    ASSERT_TRUE(ours.ok()) << ext << ": " << ours.status().message();
    const cv::Mat reference =
        cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_COLOR);
    // Same library underneath; JPEG may differ by the IDCT/upsampling choice by a level or two.
    EXPECT_LE(cv::norm(*ours, reference, cv::NORM_INF), ext == ".png" ? 0 : 8) << ext;
  }
  // Greyscale, progressive, 16-bit and alpha inputs all come out as 8-bit BGR.
  const cv::Mat1b grey(9, 7, uchar{90});
  EXPECT_TRUE(DecodeImage(testing::Encode(grey, ".jpg"), ImageLimits{}).ok());
  std::vector<uchar> progressive;
  cv::imencode(".jpg", frame, progressive, {cv::IMWRITE_JPEG_PROGRESSIVE, 1});
  EXPECT_TRUE(DecodeImage(std::string(progressive.begin(), progressive.end()), ImageLimits{}).ok());
  cv::Mat deep;
  frame.convertTo(deep, CV_16UC3, 256);
  const Result<cv::Mat3b> from_deep = DecodeImage(testing::Encode(deep, ".png"), ImageLimits{});
  ASSERT_TRUE(from_deep.ok()) << from_deep.status().message();
  EXPECT_EQ((*from_deep)(3, 3), frame(3, 3));
  cv::Mat alpha;
  cv::cvtColor(frame, alpha, cv::COLOR_BGR2BGRA);
  EXPECT_TRUE(DecodeImage(testing::Encode(alpha, ".png"), ImageLimits{}).ok());
}

TEST(StrictDecoderTest, DecoderWarningsAreErrors) {
  const std::string jpeg = testing::Encode(Textured(160, 96), ".jpg");
  std::string zeroed = jpeg;
  std::fill(zeroed.begin() + static_cast<long>(zeroed.size() / 2), zeroed.end(), '\0');
  std::string garbled = jpeg;
  for (size_t i = garbled.size() / 3; i < garbled.size() / 3 + 40; ++i) garbled[i] = '\xff';
  for (const std::string& bad : {jpeg.substr(0, jpeg.size() * 2 / 3), zeroed, garbled}) {
    const Status status = DecodeImage(bad, ImageLimits{}).status();
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << status.message();
    EXPECT_NE(status.message().find("cannot decode JPEG"), std::string::npos) << status.message();
  }
  const std::string png = testing::Encode(Textured(160, 96), ".png");
  std::string flipped = png;
  flipped[png.size() / 2] = static_cast<char>(flipped[png.size() / 2] ^ 0x55);  // CRC mismatch
  for (const std::string& bad : {png.substr(0, png.size() - 1), flipped}) {
    const Status status = DecodeImage(bad, ImageLimits{}).status();
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << status.message();
  }
}

TEST(StrictDecoderTest, PixelLimitIsCheckedOnTheDecodersOwnHeader) {
  // The decoders refuse by the size their own header parser reads, independently of the
  // admission-time peek (a second guard, before any pixel memory is allocated).
  const std::string jpeg = testing::Encode(Textured(64, 32), ".jpg");
  const std::string png = testing::Encode(Textured(64, 32), ".png");
  EXPECT_EQ(DecodeJpegStrict(jpeg, 64 * 32 - 1).status().code(), StatusCode::kResourceExhausted);
  EXPECT_EQ(DecodePngStrict(png, 64 * 32 - 1).status().code(), StatusCode::kResourceExhausted);
  EXPECT_TRUE(DecodeJpegStrict(jpeg, 64 * 32).ok());
  EXPECT_TRUE(DecodePngStrict(png, 64 * 32).ok());
}

TEST(ImageCodecTest, ProbabilityPngIsScaledAndClamped) {
  cv::Mat1f probability(2, 3);
  probability << 0.f, 0.5f, 1.f, -0.2f, 1.7f, 0.1f;
  const Result<std::string> png = EncodeProbabilityPng(probability);
  ASSERT_TRUE(png.ok());
  const std::vector<uchar> bytes(png->begin(), png->end());
  const cv::Mat map = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(map.type(), CV_8UC1);
  // round(255 * P), clamped to [0, 255]: 0.5 -> 127.5 -> 128, 0.1 -> 25.5 -> 26.
  EXPECT_EQ(map.at<uchar>(0, 0), 0);
  EXPECT_EQ(map.at<uchar>(0, 1), 128);
  EXPECT_EQ(map.at<uchar>(0, 2), 255);
  EXPECT_EQ(map.at<uchar>(1, 0), 0);
  EXPECT_EQ(map.at<uchar>(1, 1), 255);
  EXPECT_EQ(map.at<uchar>(1, 2), 26);
  EXPECT_FALSE(EncodeProbabilityPng(cv::Mat1f()).ok());
}

// ---- WebP ------------------------------------------------------------------------------------

std::string Webp(const cv::Mat& frame, int quality) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(".webp", frame, bytes, {cv::IMWRITE_WEBP_QUALITY, quality}));
  return std::string(bytes.begin(), bytes.end());
}

// A hand-written extended-format header: RIFF, "VP8X" with the given flags and canvas size,
// and nothing after it.
std::string Vp8xHeader(uint8_t flags, int width, int height) {
  std::string b = "RIFF";
  b += std::string("\x16\0\0\0", 4);  // RIFF size: "WEBP" + the 18-byte VP8X chunk
  b += "WEBPVP8X";
  b += std::string("\x0a\0\0\0", 4);
  b += static_cast<char>(flags);
  b += std::string(3, '\0');
  for (int side : {width - 1, height - 1})
    for (int k = 0; k < 3; ++k) b += static_cast<char>((side >> (8 * k)) & 0xFF);
  return b;
}

TEST(ImageHeaderTest, ReadsWebpSizesWithoutDecoding) {
  const cv::Mat3b frame = testing::RoadFrame(321, 123);
  for (const int quality : {80, 101}) {  // lossy (VP8) and lossless (VP8L, quality > 100)
    const Result<ImageHeader> webp = PeekImageHeader(Webp(frame, quality));
    ASSERT_TRUE(webp.ok()) << webp.status().message();
    EXPECT_EQ(webp->format, ImageFormat::kWebp);
    EXPECT_EQ(webp->size, cv::Size(321, 123)) << quality;
  }
  const Result<ImageHeader> extended = PeekImageHeader(Vp8xHeader(0, 5000, 4000));
  ASSERT_TRUE(extended.ok()) << extended.status().message();
  EXPECT_EQ(extended->size, cv::Size(5000, 4000));
  EXPECT_FALSE(PeekImageHeader(Webp(frame, 80).substr(0, 16)).ok());
}

TEST(StrictDecoderTest, DecodesWebpLikeOpenCv) {
  const cv::Mat3b frame = Textured(97, 41);
  for (const int quality : {80, 101}) {
    const std::string bytes = Webp(frame, quality);
    const Result<cv::Mat3b> ours = DecodeImage(bytes, ImageLimits{});
    ASSERT_TRUE(ours.ok()) << quality << ": " << ours.status().message();
    const cv::Mat reference =
        cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_COLOR);
    EXPECT_EQ(cv::norm(*ours, reference, cv::NORM_INF), 0) << quality;
  }
  // Lossless is lossless; alpha is dropped.
  const Result<cv::Mat3b> lossless = DecodeImage(Webp(frame, 101), ImageLimits{});
  ASSERT_TRUE(lossless.ok());
  EXPECT_EQ(cv::norm(*lossless, frame, cv::NORM_INF), 0);
  cv::Mat alpha;
  cv::cvtColor(frame, alpha, cv::COLOR_BGR2BGRA);
  const Result<cv::Mat3b> from_alpha = DecodeImage(Webp(alpha, 101), ImageLimits{});
  ASSERT_TRUE(from_alpha.ok()) << from_alpha.status().message();
  EXPECT_EQ(cv::norm(*from_alpha, frame, cv::NORM_INF), 0);
}

TEST(StrictDecoderTest, TruncatedAnimatedOrHugeWebpIsRefused) {
  for (const int quality : {80, 101}) {
    const std::string webp = Webp(Textured(160, 96), quality);
    for (const std::string& bad :
         {webp.substr(0, webp.size() / 2), webp.substr(0, webp.size() - 1), webp.substr(0, 30)}) {
      const Status status = DecodeImage(bad, ImageLimits{}).status();
      EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << quality << ": " << status.message();
      EXPECT_NE(status.message().find("WebP"), std::string::npos) << status.message();
    }
  }
  const Status animated = DecodeWebpStrict(Vp8xHeader(0x02, 64, 32), 1 << 20).status();
  EXPECT_EQ(animated.code(), StatusCode::kInvalidArgument) << animated.message();
  // The pixel limit holds on the header, before any pixel memory: a 5000 x 4000 canvas in 30 bytes.
  const Status huge = DecodeImage(Vp8xHeader(0, 5000, 4000), ImageLimits{}).status();
  EXPECT_EQ(huge.code(), StatusCode::kResourceExhausted) << huge.message();
  EXPECT_NE(huge.message().find("5000x4000"), std::string::npos) << huge.message();
  const std::string small = Webp(Textured(64, 32), 80);
  EXPECT_EQ(DecodeWebpStrict(small, 64 * 32 - 1).status().code(), StatusCode::kResourceExhausted);
  EXPECT_TRUE(DecodeWebpStrict(small, 64 * 32).ok());
}

}  // namespace
}  // namespace tod::server
