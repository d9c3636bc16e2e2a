// Image header peeking and decoding limits.
#include <gtest/gtest.h>

#include "server/core/image_codec.h"
#include "server/core/image_header.h"
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
  EXPECT_NE(garbage.message().find("not a JPEG or PNG"), std::string::npos);
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

}  // namespace
}  // namespace tod::server
