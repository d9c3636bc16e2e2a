#include "client/corrupt_bodies.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

namespace tod::client {
namespace {

std::string Encode(const cv::Mat& image, const char* extension) {
  std::vector<uchar> bytes;
  if (!cv::imencode(extension, image, bytes)) return {};
  return std::string(bytes.begin(), bytes.end());
}

// Half of a valid file: the header is intact, so the server only finds out while decoding.
std::string FirstHalf(const std::string& bytes) { return bytes.substr(0, bytes.size() / 2); }

std::string Noise(size_t size, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::string noise(size, '\0');
  for (char& c : noise) c = static_cast<char>(byte(random));
  return noise;
}

}  // namespace

std::vector<RequestBody> CorruptBodies(const std::string& frame_bytes, uint32_t seed) {
  std::vector<RequestBody> bodies;
  const cv::Mat encoded(1, static_cast<int>(frame_bytes.size()), CV_8UC1,
                        const_cast<char*>(frame_bytes.data()));
  const cv::Mat image = cv::imdecode(encoded, cv::IMREAD_COLOR);
  if (!image.empty()) {
    const std::string jpeg = Encode(image, ".jpg");
    const std::string png = Encode(image, ".png");
    if (!jpeg.empty()) bodies.push_back({"truncated JPEG", FirstHalf(jpeg), "image/jpeg"});
    if (!png.empty()) bodies.push_back({"truncated PNG", FirstHalf(png), "image/png"});
  }
  bodies.push_back(
      {"garbage", Noise(std::max<size_t>(frame_bytes.size(), 1024), seed), "image/png"});
  return bodies;
}

}  // namespace tod::client
