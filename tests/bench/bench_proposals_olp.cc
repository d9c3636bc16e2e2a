// OLP box scoring speed (ALGORITHM.md §4.2, §8.4) on the four LAF region sizes with their MS
// stride factors, on two synthetic superpixel-boundary maps (thin closed contours of a jittered-
// grid Voronoi tessellation, cell 40 px, ~5 % of the pixels non-zero):
//   worst: every boundary strength uniform in [0.05, 1] - almost every boundary is an edge
//          (> edge_min_mag 0.1), the stress case;
//   real:  what the pipeline feeds (a trained occlusion probability normalised by its maximum):
//          70 % of the boundary segments weak (< 0.1, below edge_min_mag), the rest 0.1 - 0.6,
//          plus strong (0.8 - 1) closed contours around a few small objects.
// Prints per map and region: windows visited, windows that ran the boundary-affinity walk,
// windows with a non-zero score, all scorings that ran a walk, boxes out, median CPU and wall
// milliseconds, and a digest of the returned boxes and scores (to check that a speed-up is exact).
// With refine_limit > 0 (the approximation, see EdgeBoxParams) it also prints, against the exact
// run: the recall of the planted objects (IoU >= 0.5 / 0.7) within the top-1000 boxes, and the
// fraction of the exact top-1000 boxes that the approximate top-1000 still contains.
//
// Usage: bench_proposals_olp [repeats [map [region [threads [refine_limit]]]]]
//        (map / region "all" = every one)
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/proposals/edge_box_scorer.h"

namespace {

// Voronoi labels of seeds on a jittered grid (cell size `cell`).
cv::Mat1i VoronoiLabels(int width, int height, int cell, std::mt19937& rng) {
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
  return labels;
}

// A deterministic value in [0, 1] per unordered label pair (one boundary segment), salted.
float PairHash(int a, int b, unsigned salt) {
  unsigned h = static_cast<unsigned>(std::min(a, b)) * 2654435761u ^
               static_cast<unsigned>(std::max(a, b)) * 40503u ^ salt * 97u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<float>(h % 1000u) / 999.f;
}

// Boundary pixels (label differs from the right or lower neighbour) with a strength per segment.
template <typename Strength>
cv::Mat1f BoundaryMap(const cv::Mat1i& labels, Strength strength) {
  cv::Mat1f map(labels.size(), 0.f);
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      const int l = labels(y, x);
      if (x + 1 < labels.cols && labels(y, x + 1) != l) map(y, x) = strength(l, labels(y, x + 1));
      if (y + 1 < labels.rows && labels(y + 1, x) != l) {
        map(y, x) = std::max(map(y, x), strength(l, labels(y + 1, x)));
      }
    }
  }
  return map;
}

cv::Mat1f WorstCaseMap(int width, int height, std::vector<tod::Box>* /*objects*/) {
  std::mt19937 rng(7);
  const cv::Mat1i labels = VoronoiLabels(width, height, 40, rng);
  return BoundaryMap(labels, [](int a, int b) { return 0.05f + 0.95f * PairHash(a, b, 0); });
}

cv::Mat1f RealisticMap(int width, int height, std::vector<tod::Box>* objects) {
  std::mt19937 rng(11);
  const cv::Mat1i labels = VoronoiLabels(width, height, 40, rng);
  cv::Mat1f map = BoundaryMap(labels, [](int a, int b) {
    const float u = PairHash(a, b, 1), v = PairHash(a, b, 2);
    return u < 0.7f ? 0.01f + 0.08f * v : 0.1f + 0.5f * v * v;
  });
  // A few small obstacles per 10^5 px, with strong closed contours.
  const int count = std::max(2, width * height / 100000);
  std::uniform_int_distribution<int> cx(20, width - 21), cy(20, height - 21), axis(4, 25);
  std::uniform_real_distribution<float> strong(0.8f, 1.f);
  for (int i = 0; i < count; ++i) {
    const cv::Point centre(cx(rng), cy(rng));
    const cv::Size axes(axis(rng), axis(rng));
    cv::ellipse(map, centre, axes, 0.0, 0.0, 360.0, cv::Scalar(strong(rng)), 1, cv::LINE_8);
    objects->push_back(tod::Box{centre.x - axes.width, centre.y - axes.height, 2 * axes.width + 1,
                                2 * axes.height + 1});
  }
  return map;
}

// FNV-1a over boxes and score bits: equal digests mean identical output.
std::uint64_t Digest(const std::vector<tod::ScoredBox>& boxes) {
  std::uint64_t h = 1469598103934665603ull;
  const auto mix = [&h](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) {
      h ^= (v >> (8 * i)) & 0xffu;
      h *= 1099511628211ull;
    }
  };
  for (const tod::ScoredBox& b : boxes) {
    std::uint32_t score_bits = 0;
    std::memcpy(&score_bits, &b.score, sizeof score_bits);
    for (const int v : {b.box.x, b.box.y, b.box.w, b.box.h}) mix(static_cast<std::uint32_t>(v));
    mix(score_bits);
  }
  return h;
}

// Fraction of the planted objects that one of the first `top` boxes covers with IoU >= iou.
double Recall(const std::vector<tod::Box>& objects, const std::vector<tod::ScoredBox>& boxes,
              size_t top, double iou) {
  if (objects.empty()) return 0.0;
  int found = 0;
  for (const tod::Box& object : objects) {
    for (size_t i = 0; i < std::min(top, boxes.size()); ++i) {
      if (tod::BoxIoU(object, boxes[i].box) >= iou) {
        ++found;
        break;
      }
    }
  }
  return static_cast<double>(found) / static_cast<double>(objects.size());
}

// Fraction of the first `top` reference boxes that reappear (same box) among the first `top`.
double SameTop(const std::vector<tod::ScoredBox>& reference,
               const std::vector<tod::ScoredBox>& other, size_t top) {
  const size_t n = std::min(top, reference.size());
  if (n == 0) return 1.0;
  int same = 0;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < std::min(top, other.size()); ++j) {
      if (other[j].box == reference[i].box) {
        ++same;
        break;
      }
    }
  }
  return static_cast<double>(same) / static_cast<double>(n);
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// `repeats` scorings of one map: the last one's boxes and counts, every one's wall and CPU ms.
struct TimedScoring {
  tod::EdgeBoxStats stats;
  std::vector<tod::ScoredBox> boxes;
  std::vector<double> wall_ms, cpu_ms;
};

TimedScoring ScoreRepeatedly(const cv::Mat1f& map, const tod::EdgeBoxParams& params, int repeats) {
  TimedScoring out;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    out.boxes = tod::ScoreEdgeBoxes(map, params, &out.stats);
    const std::clock_t c1 = std::clock();
    const auto t1 = std::chrono::steady_clock::now();
    out.wall_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    out.cpu_ms.push_back(1000.0 * static_cast<double>(c1 - c0) / CLOCKS_PER_SEC);
  }
  return out;
}

// What refining only refine_limit windows costs in recall against refining every one.
void PrintRefineRecall(const cv::Mat1f& map, const tod::EdgeBoxParams& params,
                       const std::vector<tod::Box>& objects,
                       const std::vector<tod::ScoredBox>& limited) {
  tod::EdgeBoxParams exact_params = params;
  exact_params.refine_limit = 0;
  const auto exact = tod::ScoreEdgeBoxes(map, exact_params);
  std::printf(
      "       %zu objects, top-1000 recall@0.5 %.2f -> %.2f, @0.7 %.2f -> %.2f, "
      "exact top-1000 kept %.3f\n",
      objects.size(), Recall(objects, exact, 1000, 0.5), Recall(objects, limited, 1000, 0.5),
      Recall(objects, exact, 1000, 0.7), Recall(objects, limited, 1000, 0.7),
      SameTop(exact, limited, 1000));
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
  const std::string only_map = argc > 2 ? argv[2] : "all";
  const std::string only_region = argc > 3 ? argv[3] : "all";
  const int threads = argc > 4 ? std::atoi(argv[4]) : 1;
  const int refine_limit = argc > 5 ? std::atoi(argv[5]) : 0;
  struct Region {
    const char* name;
    int width, height;
    float ms_factor;  // the region's stride factor under MS (§4.2.6)
  };
  // LAF region sizes (§1.3).
  const Region regions[] = {{"R1", 1893, 615, 1.f},
                            {"R2", 949, 404, 0.75f},
                            {"R3", 433, 297, 0.5f},
                            {"R4", 341, 141, 0.25f}};
  struct MapKind {
    const char* name;
    cv::Mat1f (*make)(int, int, std::vector<tod::Box>*);
  };
  const MapKind maps[] = {{"real", RealisticMap}, {"worst", WorstCaseMap}};
  std::printf("threads %d, refine_limit %d, %d repeats, medians\n", threads, refine_limit, repeats);
  std::printf("%-6s %-6s %10s %6s %6s %10s %10s %8s %10s %6s %8s %8s %16s\n", "map", "region",
              "size", "factor", "edge%", "windows", "walks", "nonzero", "scorings", "boxes",
              "cpu_ms", "wall_ms", "digest");
  for (const MapKind& kind : maps) {
    if (only_map != "all" && only_map != kind.name) continue;
    double cpu_total = 0.0, wall_total = 0.0;
    for (const Region& region : regions) {
      if (only_region != "all" && only_region != region.name) continue;
      std::vector<tod::Box> objects;
      const cv::Mat1f map = tod::NormaliseToMax(kind.make(region.width, region.height, &objects));
      const double edge_percent = 100.0 * cv::countNonZero(map > 0.1f) / double(map.total());
      tod::EdgeBoxParams params;
      params.stride_factor = region.ms_factor;
      params.threads = threads;
      params.refine_limit = refine_limit;
      const TimedScoring timed = ScoreRepeatedly(map, params, repeats);
      const tod::EdgeBoxStats& stats = timed.stats;
      const std::vector<tod::ScoredBox>& last = timed.boxes;
      const std::uint64_t digest = Digest(last);
      const std::vector<double>& cpu_ms = timed.cpu_ms;
      const std::vector<double>& wall_ms = timed.wall_ms;
      // CPU time is what the budget is about on a shared machine (it sums over threads).
      cpu_total += Median(cpu_ms);
      wall_total += Median(wall_ms);
      std::printf(
          "%-6s %-6s %5dx%-4d %6.2f %6.2f %10lld %10lld %8lld %10lld %6lld %8.1f %8.1f %016llx\n",
          kind.name, region.name, region.width, region.height, region.ms_factor, edge_percent,
          stats.windows_visited, stats.windows_past_early_exit, stats.windows_nonzero,
          stats.scorings, stats.boxes_out, Median(cpu_ms), Median(wall_ms),
          static_cast<unsigned long long>(digest));
      if (refine_limit > 0 && !objects.empty()) PrintRefineRecall(map, params, objects, last);
    }
    std::printf("%-6s total: %.1f ms CPU, %.1f ms wall\n", kind.name, cpu_total, wall_total);
  }
  return 0;
}
