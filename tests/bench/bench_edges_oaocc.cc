// Benchmark: sticky superpixels and occlusion painting (ALGORITHM.md §3.2(1), §3.4) on a
// 1800x620 textured synthetic crop. Prints a table of medians; nothing is asserted.
#include <algorithm>
#include <cstdio>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/edges/occlusion_classifier.h"
#include "core/edges/sticky_superpixels.h"
#include "tests/bench/bench_clock.h"

namespace {

using tod::bench::ThreadCpuMs;

using tod::OcclusionClassifier;
using tod::StickySuperpixelParams;
using tod::Superpixels;

double MedianMs(int runs, const std::function<void()>& work) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const double start = ThreadCpuMs();
    work();
    ms.push_back(ThreadCpuMs() - start);
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

// Road-like crop: noisy grey with a vertical shading, coloured discs and grey patches; labels
// mark road 1, objects 2.., so a classifier can be trained on smaller versions of it.
struct Scene {
  cv::Mat3b image;
  cv::Mat1i labels;
};

Scene MakeScene(int width, int height, int seed) {
  cv::RNG rng(seed);
  Scene s;
  s.image = cv::Mat3b(height, width);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int v = 90 + y * 40 / height + rng.uniform(-10, 11);
      s.image(y, x) = cv::Vec3b(v, v, v + 4);
    }
  s.labels = cv::Mat1i(height, width, 1);
  const int area_scale = width * height / 20000;
  for (int i = 0; i < area_scale; ++i) {
    const cv::Rect patch(rng.uniform(0, width - 60), rng.uniform(0, height - 30),
                         rng.uniform(10, 60), rng.uniform(8, 30));
    const int grey = rng.uniform(60, 160);
    s.image(patch).setTo(cv::Scalar(grey, grey, grey));
  }
  for (int i = 0; i < area_scale / 2; ++i) {
    cv::Mat1b disc(height, width, uchar{0});
    cv::circle(disc, {rng.uniform(0, width), rng.uniform(0, height)}, rng.uniform(4, 25),
               cv::Scalar(255), cv::FILLED);
    s.image.setTo(cv::Scalar(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256)), disc);
    s.labels.setTo(2 + i, disc);
  }
  return s;
}

cv::Mat1f EnhancedEdge(const cv::Mat3b& image) {
  cv::Mat1b gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  cv::Mat1f g;
  gray.convertTo(g, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(g, g, cv::Size(5, 5), 1.0);
  cv::Mat1f gx, gy, magnitude;
  cv::Sobel(g, gx, CV_32F, 1, 0);
  cv::Sobel(g, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, magnitude);
  magnitude = cv::min(magnitude, 1.0f);
  // Multilayer enhancement: the lower rows lie in more regions (factor 1..4, §2.2).
  for (int y = 0; y < magnitude.rows; ++y) magnitude.row(y) *= 1 + (4 * y) / magnitude.rows;
  return magnitude;
}

}  // namespace

int main() {
  constexpr int kRuns = 5;
  cv::setNumThreads(1);  // OpenCV's own workers would escape the thread-CPU clock
  const Scene scene = MakeScene(1800, 620, 1);
  const cv::Mat1f edge = EnhancedEdge(scene.image);

  std::vector<tod::OcclusionTrainingFrame> frames;
  for (int seed = 2; seed <= 3; ++seed) {
    const Scene small = MakeScene(600, 300, seed);
    tod::OcclusionTrainingFrame f;
    f.image = small.image;
    f.enhanced_edge = EnhancedEdge(small.image);
    f.superpixels = std::move(tod::ComputeStickySuperpixels(f.image, f.enhanced_edge)).value();
    f.labels = small.labels;
    frames.push_back(f);
  }
  tod::OcclusionParams params;  // 400 trees, the default
  params.forest.threads = 1;
  const OcclusionClassifier trained = std::move(OcclusionClassifier::Fit(frames, params)).value();
  const OcclusionClassifier fallback;

  std::printf("crop 1800x620, single thread, median thread-CPU ms of %d runs\n", kRuns);
  std::printf("%-8s %-14s %10s %14s %18s %16s\n", "k", "superpixels", "sp ms", "paint ms (fb)",
              "paint ms (forest)", "boundary px");
  for (const int k : {1024, 16384}) {
    StickySuperpixelParams sp_params;
    sp_params.k = k;
    Superpixels sp;
    const double sp_ms = MedianMs(kRuns, [&] {
      sp = std::move(tod::ComputeStickySuperpixels(scene.image, edge, sp_params)).value();
    });
    const double fb_ms = MedianMs(kRuns, [&] { (void)fallback.Paint(scene.image, edge, sp, {}); });
    const double forest_ms =
        MedianMs(kRuns, [&] { (void)trained.Paint(scene.image, edge, sp, {}); });
    std::printf("%-8d %-14d %10.1f %14.1f %18.1f %16d\n", k, sp.count, sp_ms, fb_ms, forest_ms,
                cv::countNonZero(sp.labels == 0));
  }
  std::printf("forest: %s, %d trees\n", trained.trained() ? "trained" : "UNTRAINED",
              params.forest.num_trees);
  return 0;
}
