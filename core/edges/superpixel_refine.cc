#include "core/edges/superpixel_refine.h"

#include <algorithm>
#include <array>
#include <limits>
#include <utility>
#include <vector>

namespace tod {
namespace {

// Running sums of one label, so that means update in O(1) when a pixel moves. One cache line
// per label: every cost evaluation reads a neighbouring label's sums, and a 56-byte record
// would straddle two lines most of the time.
struct alignas(64) LabelSums {
  double count = 0.0;
  double x = 0.0;
  double y = 0.0;
  double c0 = 0.0;
  double c1 = 0.0;
  double c2 = 0.0;
  double inverse_count = 0.0;  // 1 / count (0 when empty): a division per move, not per cost

  void Add(double sign, int px, int py, const float* c) {
    count += sign;
    inverse_count = count > 0 ? 1.0 / count : 0.0;
    x += sign * px;
    y += sign * py;
    c0 += sign * c[0];
    c1 += sign * c[1];
    c2 += sign * c[2];
  }
};
static_assert(sizeof(LabelSums) == 64);

// Renumbers `labels` in place to 0..n-1 in order of first appearance, carrying the sums of every
// label (if any yet) along bit for bit, and keeps `original_id` (original id of every current one)
// up to date. The refinement only compares labels for equality and indexes the sums with them, so
// it makes the same moves on the renumbered map; what changes is that the sums of the labels in use
// sit next to each other instead of being spread over an array as large as the largest id: at half
// resolution most of the one-pixel labels die in the first sweeps, and at full resolution the
// ~10^4 labels carry ids up to ~3·10^5.
void RenumberDensely(std::vector<int>& labels, std::vector<LabelSums>& sums,
                     std::vector<int>& original_id) {
  std::vector<int> dense_id(original_id.size(), -1);
  std::vector<int> dense_original;
  for (int& label : labels) {
    int& id = dense_id[label];
    if (id < 0) {
      id = static_cast<int>(dense_original.size());
      dense_original.push_back(original_id[label]);
    }
    label = id;
  }
  if (!sums.empty()) {
    std::vector<LabelSums> dense_sums(dense_original.size());
    for (size_t old = 0; old < dense_id.size(); ++old) {
      if (dense_id[old] >= 0) dense_sums[dense_id[old]] = sums[old];
    }
    sums = std::move(dense_sums);
  }
  original_id = std::move(dense_original);
}

}  // namespace

StickyWeights StickyWeightsFor(int k, double alpha, double beta) {
  StickyWeights w;
  w.size = k * alpha / 1e4;
  w.position = alpha / 1e4;
  w.edge = (1.0 - alpha) * beta;
  w.colour = (1.0 - alpha) * (1.0 - beta);
  return w;
}

int RefineStickyLabels(const StickyImage& image, const StickyWeights& weights, int iterations,
                       std::vector<int>& labels) {
  const int width = image.width;
  const int height = image.height;
  if (width <= 0 || height <= 0 || labels.empty()) return 0;
  const int max_label = *std::max_element(labels.begin(), labels.end());
  std::vector<int> original_id(static_cast<size_t>(max_label) + 1);
  for (size_t id = 0; id < original_id.size(); ++id) original_id[id] = static_cast<int>(id);
  std::vector<LabelSums> sums;
  RenumberDensely(labels, sums, original_id);
  sums.resize(original_id.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      sums[labels[i]].Add(1.0, x, y, image.colour + 3 * i);
    }
  }

  int sweeps = 0;
  for (int iter = 0; iter < iterations; ++iter) {
    ++sweeps;
    long long moved = 0;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const size_t i = static_cast<size_t>(y) * width + x;
        const int own = labels[i];
        // Interior pixels (every 4-neighbour shares the label) cannot move: decided from the
        // labels alone, before any edge value is loaded.
        const bool on_border =
            (x > 0 && labels[i - 1] != own) || (y > 0 && labels[i - width] != own) ||
            (x + 1 < width && labels[i + 1] != own) || (y + 1 < height && labels[i + width] != own);
        if (!on_border) continue;
        // 4-neighbours in the order left, up, right, down (ties go to the earliest candidate).
        std::array<int, 4> nb_label;
        std::array<float, 4> nb_edge;
        int nb_count = 0;
        auto push = [&](size_t j) {
          nb_label[nb_count] = labels[j];
          nb_edge[nb_count] = image.edge[j];
          ++nb_count;
        };
        if (x > 0) push(i - 1);
        if (y > 0) push(i - width);
        if (x + 1 < width) push(i + 1);
        if (y + 1 < height) push(i + width);

        const float* c = image.colour + 3 * i;
        const double px = x;
        const double py = y;
        auto cost = [&](int t) {
          const LabelSums& s = sums[t];
          // Size counted as if the pixel belonged to t (it already does when t is its own label):
          // with every pixel its own label initially this is what lets singletons merge.
          const double n = s.count + (t == own ? 0.0 : 1.0);
          const double inv = s.inverse_count;
          const double dx = px - s.x * inv;
          const double dy = py - s.y * inv;
          const double d0 = c[0] - s.c0 * inv;
          const double d1 = c[1] - s.c1 * inv;
          const double d2 = c[2] - s.c2 * inv;
          // e_t: weakest edge among the neighbours that would be across a boundary from the
          // pixel if it took label t; no such neighbour means no boundary at all, rewarded as
          // the strongest neighbouring edge.
          float e_min = std::numeric_limits<float>::max();
          float e_max = 0.f;
          for (int k = 0; k < nb_count; ++k) {
            e_max = std::max(e_max, nb_edge[k]);
            if (nb_label[k] != t) e_min = std::min(e_min, nb_edge[k]);
          }
          const double e_t = e_min == std::numeric_limits<float>::max() ? e_max : e_min;
          return weights.position * (dx * dx + dy * dy) +
                 weights.colour * (d0 * d0 + d1 * d1 + d2 * d2) - weights.edge * e_t +
                 weights.size / n;
        };

        int best = own;
        double best_cost = cost(own);
        for (int k = 0; k < nb_count; ++k) {
          const int t = nb_label[k];
          if (t == own || t == best) continue;
          bool seen = false;
          for (int m = 0; m < k; ++m) seen |= nb_label[m] == t;
          if (seen) continue;
          const double ct = cost(t);
          if (ct < best_cost) {
            best_cost = ct;
            best = t;
          }
        }
        if (best != own) {
          sums[own].Add(-1.0, x, y, c);
          sums[best].Add(1.0, x, y, c);
          labels[i] = best;
          ++moved;
        }
      }
    }
    if (moved == 0) break;
    if (iter + 1 < iterations) {
      // Compact once at least half of the labels have emptied (a pass over the labels, cheap
      // next to a sweep).
      const auto alive =
          std::count_if(sums.begin(), sums.end(), [](const LabelSums& s) { return s.count > 0; });
      if (2 * static_cast<size_t>(alive) <= sums.size()) RenumberDensely(labels, sums, original_id);
    }
  }
  for (int& label : labels) label = original_id[label];
  return sweeps;
}

}  // namespace tod
