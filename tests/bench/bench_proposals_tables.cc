// Cost of BoxScorer's per-map tables (ALGORITHM.md §4.1-4.2: NaN-free copy, orientation, edge
// groups, integral images, containment bound, run indexes, walk graph), i.e. of the constructor
// alone, on maps the size of the four LAF regions of a 2048x1024 frame.
//
// Maps: by default synthetic ones shaped like the normalised occlusion maps the pipeline feeds
// (~15 % of the pixels weakly non-zero, a few % edge pixels > edge_min_mag on thin contours);
// or, with MAP_DIR, every MAP_DIR/*.bin file (int rows, int cols, then rows * cols floats, row
// major), e.g. real region maps dumped from the pipeline.
// Prints per map: size, edge-pixel percentage, group count, the median thread-CPU milliseconds of
// a construction, and a digest of the groups and of the scores of a fixed set of windows (equal
// digests before and after a change mean the tables it checks did not change).
//
// Usage: bench_proposals_tables [repeats [MAP_DIR]]
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/proposals/box_scorer.h"
#include "core/proposals/edge_box_scorer.h"
#include "tests/bench/bench_clock.h"

namespace {

using tod::bench::ThreadCpuMs;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Weak clutter (thick strokes of 0.01 - 0.09, below edge_min_mag) over ~15 % of the map, plus
// thin contours and lines of 0.1 - 1 over a few %, normalised to max 1.
cv::Mat1f SyntheticMap(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  cv::Mat1f map(height, width, 0.f);
  std::uniform_int_distribution<int> x(0, width - 1), y(0, height - 1), rad(3, 30);
  std::uniform_real_distribution<float> weak(0.01f, 0.09f), strong(0.1f, 1.f);
  while (cv::countNonZero(map) < 0.15 * static_cast<double>(map.total())) {
    cv::line(map, {x(rng), y(rng)}, {x(rng), y(rng)}, cv::Scalar(weak(rng)), 3);
  }
  const int shapes = width * height / 40000;
  for (int i = 0; i < shapes; ++i) {
    cv::circle(map, {x(rng), y(rng)}, rad(rng), cv::Scalar(strong(rng)));
    cv::line(map, {x(rng), y(rng)}, {x(rng), y(rng)}, cv::Scalar(strong(rng)));
  }
  return tod::NormaliseToMax(map);
}

cv::Mat1f ReadMap(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return {};
  int dims[2] = {0, 0};
  cv::Mat1f map;
  if (std::fread(dims, sizeof dims, 1, f) == 1 && dims[0] > 0 && dims[1] > 0) {
    map.create(dims[0], dims[1]);
    for (int r = 0; r < map.rows; ++r) {
      if (std::fread(map[r], sizeof(float), map.cols, f) != static_cast<size_t>(map.cols)) {
        map.release();
        break;
      }
    }
  }
  std::fclose(f);
  return map;
}

// FNV-1a over the group tables and the scores of a deterministic window sample.
std::uint64_t Digest(const cv::Mat1f& map, tod::BoxScorer& scorer) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&h](const void* data, size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) {
      h ^= p[i];
      h *= 1099511628211ull;
    }
  };
  const tod::EdgeGroups& g = scorer.groups();
  for (int r = 0; r < g.ids.rows; ++r) mix(g.ids[r], sizeof(int) * g.ids.cols);
  for (const auto* v : {&g.magnitude, &g.mean_x, &g.mean_y, &g.orientation, &g.affinity_value}) {
    mix(v->data(), sizeof(float) * v->size());
  }
  for (const auto* v : {&g.anchor_x, &g.anchor_y, &g.affinity_begin, &g.affinity_target}) {
    mix(v->data(), sizeof(int) * v->size());
  }
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> x(0, map.cols - 1), y(0, map.rows - 1), side(2, 120);
  for (int i = 0; i < 20000; ++i) {
    tod::ScoreWindow w;
    w.c0 = x(rng);
    w.r0 = y(rng);
    w.c1 = w.c0 + side(rng);
    w.r1 = w.r0 + side(rng);
    scorer.Score(w);
    mix(&w, sizeof w);
  }
  return h;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 7;
  struct Named {
    std::string name;
    cv::Mat1f map;
  };
  std::vector<Named> maps;
  if (argc > 2) {
    std::vector<std::string> paths;
    for (const auto& entry : std::filesystem::directory_iterator(argv[2])) {
      if (entry.path().extension() == ".bin") paths.push_back(entry.path().string());
    }
    std::sort(paths.begin(), paths.end());
    for (const std::string& p : paths) {
      cv::Mat1f map = ReadMap(p);
      if (!map.empty()) maps.push_back({std::filesystem::path(p).stem().string(), map});
    }
  } else {
    // The four region maps of a 2048x1024 frame (§1.3).
    const int sizes[4][2] = {{2048, 646}, {2048, 500}, {2048, 298}, {1416, 152}};
    for (int k = 0; k < 4; ++k) {
      char name[8];
      std::snprintf(name, sizeof name, "R%d", k + 1);
      maps.push_back(
          {name, SyntheticMap(sizes[k][0], sizes[k][1], 100 + static_cast<unsigned>(k))});
    }
  }
  const tod::EdgeBoxParams params;
  std::printf("%d repeats, median thread-CPU ms of one BoxScorer construction\n", repeats);
  std::printf("%-10s %10s %6s %8s %9s %16s\n", "map", "size", "edge%", "groups", "ctor_ms",
              "digest");
  double total = 0.0;
  for (const Named& m : maps) {
    std::vector<double> ms;
    for (int i = 0; i < repeats; ++i) {
      const double t0 = ThreadCpuMs();
      const tod::BoxScorer scorer(m.map, params);
      ms.push_back(ThreadCpuMs() - t0);
    }
    tod::BoxScorer scorer(m.map, params);
    const double edge_percent =
        100.0 * cv::countNonZero(m.map > params.edge_min_mag) / static_cast<double>(m.map.total());
    const double median = Median(ms);
    total += median;
    std::printf("%-10s %5dx%-4d %6.2f %8d %9.2f %016llx\n", m.name.c_str(), m.map.cols, m.map.rows,
                edge_percent, scorer.groups().count(), median,
                static_cast<unsigned long long>(Digest(m.map, scorer)));
  }
  std::printf("total %.2f ms\n", total);
  return 0;
}
