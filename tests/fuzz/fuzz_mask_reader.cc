// Fuzzes SampleFromObstacleMask, the core of the masks reader (core/data/masks_reader.cc), which
// turns a {0, 1, 255} mask into road / obstacle / ignore masks and obstacle instances.
// Input, first byte even ("raw"): type, width, height and flags, then one byte per mask pixel,
// mapped so that most pixels are valid labels (b < 252: 0, 1 or 255 by b % 3; otherwise 2..5).
// First byte odd: the rest is a mask file, decoded as the reader decodes it (IMREAD_UNCHANGED);
// only PNG is decoded (the reader's masks are .png) and only up to 256 K pixels.
#include <cstddef>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "core/data/masks_reader.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

using tod::fuzz::Check;

constexpr int kTypes[] = {CV_8UC1, CV_8UC1, CV_8UC1, CV_8UC3, CV_16UC1, CV_32FC1, CV_8SC1};

// width x height of a PNG from its IHDR, or 0 when the bytes are not a PNG.
long long PngPixels(const uint8_t* p, size_t n) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n < 24 || !std::equal(kSignature, kSignature + 8, p)) return 0;
  auto be32 = [p](size_t at) {
    return (uint32_t{p[at]} << 24) | (uint32_t{p[at + 1]} << 16) | (uint32_t{p[at + 2]} << 8) |
           uint32_t{p[at + 3]};
  };
  const uint64_t width = be32(16), height = be32(20);
  return width > (1u << 18) || height > (1u << 18) ? 1LL << 40
                                                   : static_cast<long long>(width * height);
}

void CheckSample(const tod::Sample& sample, const cv::Mat3b& image) {
  const cv::Size size = image.size();
  Check(sample.road.size() == size && sample.obstacle.size() == size &&
        sample.ignore.size() == size);
  const cv::Rect frame(0, 0, size.width, size.height);
  for (const tod::ObstacleInstance& instance : sample.instances) {
    Check(!instance.box.empty() && (instance.box.rect() & frame) == instance.box.rect());
    Check(instance.mask.rows == instance.box.h && instance.mask.cols == instance.box.w);
    Check(instance.pixel_count() >= tod::kMinInstancePixels);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  tod::fuzz::Bytes in(data, size);
  cv::Mat mask;
  cv::Mat3b image;
  if (in.U8() % 2 == 1) {
    const long long pixels = PngPixels(in.rest(), in.left());
    if (pixels <= 0 || pixels > (1 << 18)) return 0;
    const std::vector<uint8_t> file(in.rest(), in.rest() + in.left());
    mask = cv::imdecode(file, cv::IMREAD_UNCHANGED);
    if (mask.empty()) return 0;
    image = cv::Mat3b(mask.size(), cv::Vec3b(90, 90, 90));
  } else {
    const int type = kTypes[in.U8() % std::size(kTypes)];
    const int width = 1 + in.U8() % 64;
    const int height = 1 + in.U8() % 64;
    const uint8_t flags = in.U8();
    cv::Mat1b labels(height, width);
    for (uchar& v : labels) {
      const uint8_t b = in.U8();
      v = b < 252 ? (b % 3 == 0 ? 0 : b % 3 == 1 ? 1 : 255) : static_cast<uchar>(b - 250);
    }
    // A region of a larger matrix (rows not contiguous), as a caller's ROI would be.
    if (flags & 1) {
      cv::Mat1b wider(height, width + 3, uchar{7});
      labels.copyTo(wider.colRange(1, 1 + width));
      labels = wider.colRange(1, 1 + width);
    }
    if (type == CV_8UC1) {
      mask = labels;  // no copy: keeps the region's row stride
    } else {
      labels.convertTo(mask, CV_MAT_DEPTH(type));
    }
    if (CV_MAT_CN(type) == 3) cv::merge(std::vector<cv::Mat>{mask, mask, mask}, mask);
    const int image_width = (flags & 2) ? width + 1 : width;  // a mask of the wrong size
    if (!(flags & 4)) image = cv::Mat3b(height, image_width, cv::Vec3b(90, 90, 90));
  }
  const tod::Result<tod::Sample> sample =
      tod::SampleFromObstacleMask(image, mask, "fuzz", "fuzz.png");
  if (sample.ok()) {
    Check(mask.type() == CV_8UC1 && mask.size() == image.size());
    CheckSample(*sample, image);
  } else {
    Check(!sample.status().message().empty());
  }
  return 0;
}
