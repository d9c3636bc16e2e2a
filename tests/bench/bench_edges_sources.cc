// Speed of the base edge sources (ALGORITHM.md §3.4) on LAF-sized R1 crops. Prints medians.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/edges/edge_channels.h"
#include "core/edges/edge_source.h"
#include "tests/bench/bench_clock.h"

namespace {

using tod::bench::ThreadCpuMs;

// A crop with a grey background, a darker lower half and many coloured blobs, plus noise.
tod::EdgeTrainingFrame MakeScene(int width, int height, int seed) {
  cv::RNG rng(static_cast<std::uint64_t>(seed) + 1);
  tod::EdgeTrainingFrame frame;
  frame.image = cv::Mat3b(height, width, cv::Vec3b(140, 140, 140));
  frame.labels = cv::Mat1i::zeros(height, width);
  frame.image(cv::Rect(0, height / 2, width, height - height / 2)).setTo(cv::Vec3b(80, 80, 80));
  frame.labels(cv::Rect(0, height / 2, width, height - height / 2)).setTo(1);
  for (int k = 0; k < 40; ++k) {
    const cv::Scalar colour(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
    const cv::Point centre(rng.uniform(0, width), rng.uniform(0, height));
    const cv::Size axes(rng.uniform(4, 40), rng.uniform(4, 30));
    cv::ellipse(frame.image, centre, axes, rng.uniform(0.0, 180.0), 0, 360, colour, cv::FILLED);
    cv::ellipse(frame.labels, centre, axes, rng.uniform(0.0, 180.0), 0, 360, 2 + k, cv::FILLED);
  }
  cv::Mat noise(height, width, CV_16SC3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 6);
  cv::Mat noisy;
  frame.image.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(frame.image, CV_8UC3);
  return frame;
}

double Median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Median wall time and median CPU time of the calling thread (the CPU time is the whole cost
// only when OpenCV runs single-threaded; it is robust to other processes on a shared machine).
struct Timing {
  double wall_ms = 0;
  double cpu_ms = 0;
};

Timing Measure(const std::function<void()>& run, int repeats) {
  std::vector<double> wall;
  std::vector<double> cpu;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = ThreadCpuMs();
    run();
    cpu.push_back(ThreadCpuMs() - cpu_start);
    wall.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }
  return {Median(wall), Median(cpu)};
}

void PrintRow(const char* label, const Timing& timing, bool single_thread) {
  if (single_thread) {
    std::printf("%-44s %10.1f %12.1f\n", label, timing.wall_ms, timing.cpu_ms);
  } else {
    std::printf("%-44s %10.1f %12s\n", label, timing.wall_ms, "-");
  }
}

}  // namespace

int main() {
  const tod::EdgeTrainingFrame wide = MakeScene(2048, 600, 1);
  const tod::EdgeTrainingFrame laf = MakeScene(1800, 620, 2);
  const auto gradient = tod::CreateGradientEdgeSource();

  std::vector<tod::EdgeTrainingFrame> frames;
  for (int seed = 10; seed < 16; ++seed) frames.push_back(MakeScene(640, 240, seed));
  tod::PixelEdgeParams params;  // paper defaults: 4000 samples / frame, 8 trees, depth 20
  const auto train_start = std::chrono::steady_clock::now();
  const tod::PixelEdgeClassifier classifier =
      std::move(tod::PixelEdgeClassifier::TryTrain(frames, params)).value();
  const double train_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - train_start)
          .count();

  std::printf("%-44s %10s %12s\n", "stage", "median ms", "median cpu ms");
  std::printf("%-44s %10.1f %12s\n", "pixel_forest train (6 frames x 4000 samples)", train_ms, "-");
  for (const int threads : {1, 0}) {
    const bool single = threads == 1;
    cv::setNumThreads(single ? 1 : -1);
    const char* suffix = single ? "1 thread" : "default threads";
    char label[96];
    std::snprintf(label, sizeof(label), "gradient 2048x600 (%s)", suffix);
    PrintRow(label, Measure([&] { gradient->Compute(wide.image); }, 9), single);
    std::snprintf(label, sizeof(label), "edge channels 1800x620 (%s)", suffix);
    PrintRow(label, Measure([&] { tod::ComputeEdgeChannels(laf.image); }, 9), single);
    std::snprintf(label, sizeof(label), "pixel_forest 1800x620 (%s)", suffix);
    PrintRow(label, Measure([&] { classifier.Compute(laf.image); }, 5), single);
  }
  return classifier.trained() ? 0 : 1;
}
