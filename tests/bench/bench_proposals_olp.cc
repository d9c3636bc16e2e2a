// OLP box scoring speed on synthetic superpixel-boundary maps (ALGORITHM.md §8.4): thin closed
// contours from a jittered-grid Voronoi tessellation, ~5 % of the pixels non-zero, boundary
// strengths drawn per superpixel pair. Prints, per region size and stride factor: windows
// visited, windows past the early exit, boxes out, median milliseconds.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/proposals/edge_box_scorer.h"

namespace {

// Voronoi labels of seeds on a jittered grid (cell size `cell`), boundaries where a pixel's
// label differs from its right or lower neighbour.
cv::Mat1f SuperpixelBoundaryMap(int width, int height, int cell, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> jitter(0.f, static_cast<float>(cell));
  const int gw = width / cell + 2, gh = height / cell + 2;
  std::vector<cv::Point2f> seeds(static_cast<size_t>(gw) * gh);
  for (int gy = 0; gy < gh; ++gy) {
    for (int gx = 0; gx < gw; ++gx) {
      seeds[gy * gw + gx] = {(gx - 1) * cell + jitter(rng), (gy - 1) * cell + jitter(rng)};
    }
  }
  cv::Mat1i labels(height, width);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int gx = x / cell + 1, gy = y / cell + 1;
      float best = 1e30f;
      int best_id = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int id = (gy + dy) * gw + gx + dx;
          const float ex = seeds[id].x - x, ey = seeds[id].y - y;
          if (ex * ex + ey * ey < best) {
            best = ex * ex + ey * ey;
            best_id = id;
          }
        }
      }
      labels(y, x) = best_id;
    }
  }
  const auto strength = [](int a, int b) {
    const unsigned h = static_cast<unsigned>(std::min(a, b)) * 2654435761u ^
                       static_cast<unsigned>(std::max(a, b)) * 40503u;
    return 0.05f + 0.95f * static_cast<float>(h % 1000u) / 999.f;
  };
  cv::Mat1f map(height, width, 0.f);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int l = labels(y, x);
      if (x + 1 < width && labels(y, x + 1) != l) map(y, x) = strength(l, labels(y, x + 1));
      if (y + 1 < height && labels(y + 1, x) != l) {
        map(y, x) = std::max(map(y, x), strength(l, labels(y + 1, x)));
      }
    }
  }
  return map;
}

double MedianMs(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  // Usage: bench_proposals_olp [repeats [region name]]
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  const std::string only = argc > 2 ? argv[2] : "";
  struct Region {
    const char* name;
    int width, height;
    float ms_factor;  // the region's stride factor under MS (§4.2.6)
  };
  // LAF region sizes (§1.3) plus the 1900 x 620 target map.
  const Region regions[] = {{"target", 1900, 620, 1.f},
                            {"R1", 1893, 615, 1.f},
                            {"R2", 949, 404, 0.75f},
                            {"R3", 433, 297, 0.5f},
                            {"R4", 341, 141, 0.25f}};
  std::printf("%-7s %10s %7s %6s %10s %10s %8s %10s %6s %8s %8s\n", "region", "size", "factor",
              "edge%", "windows", "past_exit", "nonzero", "scorings", "boxes", "cpu_ms", "wall_ms");
  double ms_total = 0.0;
  for (const Region& region : regions) {
    if (!only.empty() && only != region.name) continue;
    const cv::Mat1f map =
        tod::NormaliseToMax(SuperpixelBoundaryMap(region.width, region.height, 40, 7));
    const double edge_fraction = 100.0 * cv::countNonZero(map) / static_cast<double>(map.total());
    std::vector<float> factors = {1.f};
    if (region.ms_factor < 1.f) factors.push_back(region.ms_factor);
    for (const float factor : factors) {
      tod::EdgeBoxParams params;
      params.stride_factor = factor;
      tod::EdgeBoxStats stats;
      std::vector<double> ms, cpu_ms;
      for (int i = 0; i < repeats; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        const auto boxes = tod::ScoreEdgeBoxes(map, params, &stats);
        const std::clock_t c1 = std::clock();
        const auto t1 = std::chrono::steady_clock::now();
        ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        cpu_ms.push_back(1000.0 * static_cast<double>(c1 - c0) / CLOCKS_PER_SEC);
      }
      // CPU time is what the budget is about on a shared machine; wall time is shown too.
      const double median = MedianMs(cpu_ms);
      if (region.name[0] == 'R' && factor == region.ms_factor) ms_total += median;
      std::printf("%-7s %5dx%-4d %7.2f %6.2f %10lld %10lld %8lld %10lld %6lld %8.1f %8.1f\n",
                  region.name, region.width, region.height, factor, edge_fraction,
                  stats.windows_visited, stats.windows_past_early_exit, stats.windows_nonzero,
                  stats.scorings, stats.boxes_out, median, MedianMs(ms));
    }
  }
  std::printf("4 regions with MS factors: %.1f ms CPU\n", ms_total);
  return 0;
}
