// Time to generate one synthetic frame (issue 2 asks for well under a second at 2048 x 1024).
// Prints medians of wall time and of process CPU time (the machine may be shared).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <vector>

#include "core/synth/synth.h"

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 7;
  std::printf("%-12s %8s %14s %14s\n", "size", "frames", "wall_ms_med", "cpu_ms_med");
  for (const auto& [w, h] :
       std::vector<std::pair<int, int>>{{2048, 1024}, {1024, 512}, {512, 256}}) {
    tod::SynthParams params;
    params.width = w;
    params.height = h;
    std::vector<double> wall, cpu;
    for (int i = 0; i < repeats; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const std::clock_t c0 = std::clock();
      const tod::Sample s = tod::GenerateSynthFrame(params, 1000 + i, "bench");
      cpu.push_back(1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
      wall.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (s.image.empty()) return 1;
    }
    std::printf("%4dx%-7d %8d %14.1f %14.1f\n", w, h, repeats, Median(wall), Median(cpu));
  }
  return 0;
}
