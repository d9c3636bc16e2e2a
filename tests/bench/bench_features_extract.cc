// Cost of the 20 proposal features (ALGORITHM.md §5): integral images once per region, then
// 20 000 boxes on an 1800 x 600 region. Prints medians over repeated runs; asserts nothing.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "core/features/box_features.h"

namespace {

using Clock = std::chrono::steady_clock;

double MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Edge map like a superpixel boundary map: one constant strength per boundary segment on a
// jittered grid (about 5 % of the pixels are edges), plus a smooth random colour image.
void MakeRegion(int rows, int cols, std::mt19937_64& rng, cv::Mat1f& map, cv::Mat3b& bgr) {
  std::uniform_real_distribution<float> strength(0.05f, 1.f);
  map = cv::Mat1f(rows, cols, 0.f);
  for (int x = 0; x < cols; x += 20) {
    for (int y0 = 0; y0 < rows; y0 += 20) {
      const float s = strength(rng);
      for (int y = y0; y < std::min(rows, y0 + 20); ++y) map(y, x) = s;
    }
  }
  for (int y = 0; y < rows; y += 20) {
    for (int x0 = 0; x0 < cols; x0 += 20) {
      const float s = strength(rng);
      for (int x = x0; x < std::min(cols, x0 + 20); ++x) map(y, x) = s;
    }
  }
  cv::Mat3b noise(rows / 16 + 1, cols / 16 + 1);
  cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::resize(noise, bgr, {cols, rows}, 0, 0, cv::INTER_LINEAR);
}

std::vector<tod::ScoredBox> MakeBoxes(int count, int rows, int cols, cv::Point origin, int max_side,
                                      std::mt19937_64& rng) {
  std::uniform_int_distribution<int> side(6, max_side);
  std::uniform_real_distribution<float> score(0.f, 1.f);
  std::vector<tod::ScoredBox> boxes;
  boxes.reserve(count);
  for (int i = 0; i < count; ++i) {
    const int w = side(rng), h = side(rng);
    const int x = std::uniform_int_distribution<int>(0, cols - w)(rng);
    const int y = std::uniform_int_distribution<int>(0, rows - h)(rng);
    boxes.push_back({{x + origin.x, y + origin.y, w, h}, score(rng)});
  }
  return boxes;
}

}  // namespace

int main() {
  constexpr int kRows = 600, kCols = 1800, kBoxes = 20000, kRepeats = 5;
  const cv::Point origin(124, 300);
  const cv::Size image(2048, 1024);
  std::mt19937_64 rng(2020);
  cv::Mat1f map;
  cv::Mat3b bgr;
  MakeRegion(kRows, kCols, rng, map, bgr);

  std::printf("bench_features_extract: %d boxes, region %dx%d, median of %d runs\n", kBoxes, kCols,
              kRows, kRepeats);
  std::printf("%-12s %14s %16s %14s %12s\n", "max side", "integrals ms", "20k features ms",
              "us per box", "total ms");
  for (const int max_side : {40, 120, 300}) {
    const std::vector<tod::ScoredBox> boxes =
        MakeBoxes(kBoxes, kRows, kCols, origin, max_side, rng);
    std::vector<double> build_ms, compute_ms;
    double checksum = 0.0;
    for (int r = 0; r < kRepeats; ++r) {
      const auto t0 = Clock::now();
      const tod::BoxFeatureExtractor extractor(map, bgr, origin, image);
      build_ms.push_back(MillisecondsSince(t0));
      const auto t1 = Clock::now();
      const cv::Mat1f features = extractor.ComputeAll(boxes);
      compute_ms.push_back(MillisecondsSince(t1));
      checksum += cv::sum(features)[0];
    }
    const double build = Median(build_ms), compute = Median(compute_ms);
    std::printf("%-12d %14.1f %16.1f %14.2f %12.1f   (checksum %.3g)\n", max_side, build, compute,
                1000.0 * compute / kBoxes, build + compute, checksum);
  }
  return 0;
}
