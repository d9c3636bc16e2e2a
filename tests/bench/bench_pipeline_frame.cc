// Per-stage time of one detection on a full-size frame (the speed budget: 2048 x 1024 in at most
// 1.5 s on one core, Release). Prints a table of medians (stages in wall time, and the whole
// detection in thread CPU time, which neighbours on a shared machine disturb far less); asserts
// nothing.
//   bench_pipeline_frame MODEL_DIR [REPEATS=5] [WIDTH=2048 HEIGHT=1024]
// The frame is a synthetic scene (seeded); OpenCV's own threading is off, as in the server's
// workers, so every number is one core's work.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/base/heap_tuning.h"
#include "core/pipeline/detector.h"
#include "core/synth/synth.h"
#include "tests/bench/bench_clock.h"

using tod::bench::ThreadCpuMs;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MODEL_DIR [REPEATS] [WIDTH HEIGHT]\n", argv[0]);
    return 2;
  }
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  tod::SynthParams synth;
  if (argc > 4) {
    synth.width = std::atoi(argv[3]);
    synth.height = std::atoi(argv[4]);
  }
  cv::setNumThreads(0);
  tod::RetainLargeAllocations();  // as tod and tod_server do
  auto detector = tod::Detector::Load(argv[1]);
  if (!detector.ok()) {
    std::fprintf(stderr, "%s\n", detector.status().ToString().c_str());
    return 1;
  }
  std::map<std::string, std::vector<double>> stage_ms;
  std::vector<std::string> order;
  std::size_t proposals = 0;
  for (int r = 0; r < repeats; ++r) {
    const tod::Sample frame =
        tod::GenerateSynthFrame(synth, 1000 + static_cast<unsigned>(r), "bench");
    tod::DetectOptions options;
    options.max_proposals = 1 << 30;
    const double cpu_start = ThreadCpuMs();
    auto detection = (*detector)->Detect(frame.image, options);
    stage_ms["total (thread CPU)"].push_back(ThreadCpuMs() - cpu_start);
    if (!detection.ok()) {
      std::fprintf(stderr, "%s\n", detection.status().ToString().c_str());
      return 1;
    }
    proposals += detection->proposals.size();
    double total = 0;
    for (const auto& [stage, ms] : detection->timings) {
      if (!stage_ms.count(stage)) order.push_back(stage);
      stage_ms[stage].push_back(ms);
      total += ms;
    }
    stage_ms["total"].push_back(total);
  }
  order.push_back("total");
  order.push_back("total (thread CPU)");
  std::printf("frame %dx%d, %d frames, %zu proposals per frame (mean), one core\n", synth.width,
              synth.height, repeats, proposals / repeats);
  std::printf("| stage | median ms | min ms | max ms |\n|---|---|---|---|\n");
  for (const auto& stage : order) {
    std::vector<double> v = stage_ms[stage];
    std::sort(v.begin(), v.end());
    std::printf("| %s | %.1f | %.1f | %.1f |\n", stage.c_str(), v[v.size() / 2], v.front(),
                v.back());
  }
  return 0;
}
