// Cost of the 20 proposal features (ALGORITHM.md §5) on an 1800 x 620 region of a 2048 x 1024
// frame: construction (colour tables, sparse edge map) and per-box cost for small / medium /
// large boxes, with the default (large boxes snapped, see box_features.h) and the exact colour
// contrast. Prints medians of thread CPU time (robust when the machine is shared) and of wall
// time; asserts nothing.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "core/features/box_features.h"
#include "tests/bench/bench_clock.h"

namespace {

using tod::bench::ThreadCpuMs;

struct Timing {
  double cpu_ms = 0.0;
  double wall_ms = 0.0;
};

// Median CPU and wall time of `repeats` runs of fn.
Timing MedianTiming(int repeats, const std::function<void()>& fn) {
  std::vector<double> cpu, wall;
  for (int r = 0; r < repeats; ++r) {
    const double c0 = ThreadCpuMs();
    const auto w0 = std::chrono::steady_clock::now();
    fn();
    wall.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count());
    cpu.push_back(ThreadCpuMs() - c0);
  }
  std::sort(cpu.begin(), cpu.end());
  std::sort(wall.begin(), wall.end());
  return {cpu[cpu.size() / 2], wall[wall.size() / 2]};
}

// Edge map like a superpixel boundary map: one constant strength per boundary segment on a
// jittered grid (about 10 % of the pixels are edges), plus a smooth random colour image.
void MakeRegion(int rows, int cols, std::mt19937_64& rng, cv::Mat1f& map, cv::Mat3b& bgr) {
  std::uniform_real_distribution<float> strength(0.05f, 1.f);
  std::uniform_int_distribution<int> jitter(-3, 3);
  map = cv::Mat1f(rows, cols, 0.f);
  for (int x0 = 0; x0 < cols; x0 += 20) {
    for (int y0 = 0; y0 < rows; y0 += 20) {
      const float s = strength(rng);
      const int x = std::clamp(x0 + jitter(rng), 0, cols - 1);
      for (int y = y0; y < std::min(rows, y0 + 20); ++y) map(y, x) = s;
    }
  }
  for (int y0 = 0; y0 < rows; y0 += 20) {
    for (int x0 = 0; x0 < cols; x0 += 20) {
      const float s = strength(rng);
      const int y = std::clamp(y0 + jitter(rng), 0, rows - 1);
      for (int x = x0; x < std::min(cols, x0 + 20); ++x) map(y, x) = s;
    }
  }
  cv::Mat3b noise(rows / 16 + 1, cols / 16 + 1);
  cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::resize(noise, bgr, {cols, rows}, 0, 0, cv::INTER_LINEAR);
}

// Boxes with sides log-uniform in [min_side, max_side], anywhere in the region.
std::vector<tod::ScoredBox> MakeBoxes(int count, int rows, int cols, cv::Point origin, int min_side,
                                      int max_side, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> log_side(std::log(min_side), std::log(max_side));
  std::uniform_real_distribution<float> score(0.f, 1.f);
  std::vector<tod::ScoredBox> boxes;
  boxes.reserve(count);
  for (int i = 0; i < count; ++i) {
    const int w = static_cast<int>(std::exp(log_side(rng)));
    const int h = static_cast<int>(std::exp(log_side(rng)));
    const int x = std::uniform_int_distribution<int>(0, cols - w)(rng);
    const int y = std::uniform_int_distribution<int>(0, rows - h)(rng);
    boxes.push_back({{x + origin.x, y + origin.y, w, h}, score(rng)});
  }
  return boxes;
}

}  // namespace

int main() {
  constexpr int kRows = 620, kCols = 1800, kRepeats = 7;
  const cv::Point origin(124, 300);
  const cv::Size image(2048, 1024);
  std::mt19937_64 rng(2020);
  cv::Mat1f map;
  cv::Mat3b bgr;
  MakeRegion(kRows, kCols, rng, map, bgr);

  std::printf("bench_features_extract: region %dx%d in a %dx%d frame, median of %d runs\n", kCols,
              kRows, image.width, image.height, kRepeats);
  std::printf("\nconstruction                           cpu ms    wall ms\n");
  const Timing colour = MedianTiming(kRepeats, [&] {
    const tod::ColourIntegrals integrals(bgr, origin);
    (void)integrals;
  });
  const auto shared = std::make_shared<const tod::ColourIntegrals>(bgr, origin);
  const Timing edges_only = MedianTiming(kRepeats, [&] {
    const tod::BoxFeatureExtractor extractor(shared, map, origin, image);
    (void)extractor;
  });
  const Timing full = MedianTiming(kRepeats, [&] {
    const tod::BoxFeatureExtractor extractor(map, bgr, origin, image);
    (void)extractor;
  });
  std::printf("%-36s %9.1f %10.1f\n", "colour tables (once per frame)", colour.cpu_ms,
              colour.wall_ms);
  std::printf("%-36s %9.1f %10.1f\n", "extractor on shared colour (edges)", edges_only.cpu_ms,
              edges_only.wall_ms);
  std::printf("%-36s %9.1f %10.1f\n", "extractor, per-region colour", full.cpu_ms, full.wall_ms);

  const tod::BoxFeatureExtractor fast(shared, map, origin, image);
  const tod::BoxFeatureExtractor exact(shared, map, origin, image, {.exact_contrast = true});
  struct BoxClass {
    const char* name;
    int count, min_side, max_side;
  };
  const BoxClass classes[] = {{"small 6-24", 10000, 6, 24},
                              {"medium 24-96", 10000, 24, 96},
                              {"large 96-300", 10000, 96, 300},
                              {"mix 6-300 (30k)", 30000, 6, 300}};
  std::printf("\n%-18s %7s %14s %14s %16s %16s\n", "boxes", "count", "us/box cpu", "us/box wall",
              "exact us/box cpu", "total ms cpu");
  for (const BoxClass& c : classes) {
    const std::vector<tod::ScoredBox> boxes =
        MakeBoxes(c.count, kRows, kCols, origin, c.min_side, c.max_side, rng);
    double checksum = 0.0;
    const Timing t =
        MedianTiming(kRepeats, [&] { checksum += cv::sum(fast.ComputeAll(boxes))[0]; });
    const Timing te = MedianTiming(3, [&] { checksum += cv::sum(exact.ComputeAll(boxes))[0]; });
    std::printf("%-18s %7d %14.2f %14.2f %16.2f %16.1f   (checksum %.4g)\n", c.name, c.count,
                1000.0 * t.cpu_ms / c.count, 1000.0 * t.wall_ms / c.count,
                1000.0 * te.cpu_ms / c.count, t.cpu_ms, checksum);
  }
  return 0;
}
