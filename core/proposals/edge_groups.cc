#include "core/proposals/edge_groups.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "core/proposals/edge_orientation.h"

namespace tod {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr int kNoGroup = 0;
// An interior edge pixel the greedy walk has not reached yet. Every other pixel starts as
// kNoGroup, so the label array ends up as the id map itself: no "not an edge" state to clear.
constexpr int kUnassigned = -1;

// Orientation difference of two pixels folded into [0, 0.5] (§4.2.1).
float OrientationCost(float a, float b) {
  const float v = std::fabs(a - b) / kPi;
  return v > 0.5f ? 1.f - v : v;
}

// The grouping, the dissolution sweeps and the anchor definition are all column-major
// (§4.2.1-2). They visit edge pixels only, so they walk the column-major edge list (which lists
// them in exactly that order) and work in place on the row-major id map: a neighbour (dr, dc) of
// pixel p is p + dr * w + dc, and every loop keeps its column-major visiting order and its
// (dc outer, dr inner) neighbour order, so each decision and each sum is the one a full
// column-major sweep over column-major copies makes.
struct GroupingMaps {
  const EdgePixels* edges = nullptr;
  int w = 0, h = 0;
  int* label = nullptr;          // ids, continuous: kUnassigned, kNoGroup or a group id
  const float* theta = nullptr;  // continuous, w x h; read at interior edge pixels only
};

// Calls f(entry, r, c, p) for each edge pixel with r0 <= r < h - r0 and r0 <= c < w - r0 (the
// interior at distance r0 from the border), in column-major order; p = r * w + c.
template <typename F>
void ForEachInterior(const GroupingMaps& m, int r0, F f) {
  const EdgePixels& e = *m.edges;
  for (int c = r0; c < m.w - r0; ++c) {
    for (int i = e.col_begin[c]; i < e.col_begin[c + 1]; ++i) {
      const int r = e.col_row[i];
      if (r < r0 || r >= m.h - r0) continue;
      f(i, r, c, r * m.w + c);
    }
  }
}

struct Candidate {
  int pixel;
  float cost;
};

// Greedy walk of §4.2.1: the candidate list persists across steps (the walk can branch) and
// is compacted in order while searching for its minimum, which keeps "first minimum wins".
int GreedyGrouping(GroupingMaps& m, float merge_thr) {
  const int w = m.w;
  int next_id = 1;
  std::vector<Candidate> candidates;
  ForEachInterior(m, 1, [&](int, int, int, int seed) {
    int current = seed;
    if (m.label[current] != kUnassigned) return;
    candidates.clear();
    float accumulated = 0.f;
    while (accumulated < merge_thr) {
      m.label[current] = next_id;
      const float theta0 = m.theta[current];
      for (int dc = -1; dc <= 1; ++dc) {
        for (int dr = -1; dr <= 1; ++dr) {
          const int q = current + dr * w + dc;
          if (m.label[q] != kUnassigned) continue;
          candidates.push_back({q, OrientationCost(m.theta[q], theta0)});
        }
      }
      int best = -1;
      size_t live = 0;
      for (size_t k = 0; k < candidates.size(); ++k) {
        if (m.label[candidates[k].pixel] != kUnassigned) continue;  // taken meanwhile: drop
        candidates[live] = candidates[k];
        if (best < 0 || candidates[live].cost < candidates[best].cost) {
          best = static_cast<int>(live);
        }
        ++live;
      }
      candidates.resize(live);
      if (best < 0) break;  // nothing left to walk to
      accumulated += candidates[best].cost;
      current = candidates[best].pixel;
    }
    ++next_id;
  });
  return next_id;
}

// Dissolves groups with magnitude sum <= min_mag and hands their pixels, sweep after sweep,
// to the 8-neighbour group whose pixel has the most similar orientation.
void DissolveWeakGroups(GroupingMaps& m, int id_end, float min_mag) {
  const EdgePixels& e = *m.edges;
  std::vector<double> group_mag(id_end, 0.0);
  // Summed in column-major order, as a full sweep would.
  ForEachInterior(m, 1, [&](int i, int, int, int p) {
    if (m.label[p] > 0) group_mag[m.label[p]] += e.col_value[i];
  });
  std::vector<int> pending;  // column-major order, as the full sweep would visit them
  ForEachInterior(m, 1, [&](int, int, int, int p) {
    if (m.label[p] > 0 && group_mag[m.label[p]] <= min_mag) {
      m.label[p] = kNoGroup;
      pending.push_back(p);
    }
  });
  const int w = m.w;
  bool changed = true;
  while (changed && !pending.empty()) {
    changed = false;
    size_t still_pending = 0;
    for (const int p : pending) {
      float best_cost = 1000.f;
      int best_label = kNoGroup;
      for (int dc = -1; dc <= 1; ++dc) {
        for (int dr = -1; dr <= 1; ++dr) {
          const int q = p + dr * w + dc;
          if (m.label[q] <= 0) continue;
          const float cost = OrientationCost(m.theta[q], m.theta[p]);
          if (cost < best_cost) {
            best_cost = cost;
            best_label = m.label[q];
          }
        }
      }
      m.label[p] = best_label;
      if (best_label > 0) {
        changed = true;
      } else {
        pending[still_pending++] = p;
      }
    }
    pending.resize(still_pending);
  }
}

// Relabels surviving groups 1..N in order of their old id; returns N. Only interior edge pixels
// carry labels (the greedy walk labelled all of them), every other pixel is already kNoGroup.
int Compact(GroupingMaps& m, int id_end) {
  std::vector<int> new_id(id_end, 0);
  ForEachInterior(m, 1, [&](int, int, int, int p) {
    if (m.label[p] > 0) new_id[m.label[p]] = 1;
  });
  int count = 0;
  for (int i = 1; i < id_end; ++i) {
    if (new_id[i]) new_id[i] = ++count;
  }
  ForEachInterior(m, 1, [&](int, int, int, int p) {
    const int l = m.label[p];
    m.label[p] = l > 0 ? new_id[l] : kNoGroup;
  });
  return count;
}

// Groups the edge pixels of `edges` (interior ones only: the 1-pixel map border never holds
// edge pixels, so 8-neighbour look-ups never leave the map). theta: continuous, same size, read
// at interior edge pixels only. Returns the id map and sets *count.
cv::Mat1i GroupPixels(const EdgePixels& edges, const cv::Mat1f& theta,
                      const EdgeGroupParams& params, int* count) {
  cv::Mat1i ids(edges.rows, edges.cols, kNoGroup);
  GroupingMaps m{&edges, edges.cols, edges.rows, ids.ptr<int>(0), theta.ptr<float>(0)};
  ForEachInterior(m, 1, [&](int, int, int, int p) { m.label[p] = kUnassigned; });
  const int id_end = GreedyGrouping(m, params.edge_merge_thr);
  DissolveWeakGroups(m, id_end, params.cluster_min_mag);
  *count = Compact(m, id_end);
  return ids;
}

void ComputeStatistics(const EdgePixels& edges, const cv::Mat1i& ids, const cv::Mat1f& theta,
                       int count, EdgeGroups& g) {
  const size_t n = static_cast<size_t>(count) + 1;
  std::vector<double> sum_m(n, 0.0), sum_x(n, 0.0), sum_y(n, 0.0), sum_cos(n, 0.0), sum_sin(n, 0.0);
  g.anchor_x.assign(n, 0);
  g.anchor_y.assign(n, 0);
  // Column-major over the edge pixels: the order of a full column-major scan, so every double
  // sum adds the same terms in the same order.
  for (int c = 0; c < edges.cols; ++c) {
    for (int i = edges.col_begin[c]; i < edges.col_begin[c + 1]; ++i) {
      const int r = edges.col_row[i];
      const int s = ids(r, c);
      if (s <= 0) continue;
      const double v = edges.col_value[i];
      const float t = theta(r, c);
      sum_m[s] += v;
      sum_x[s] += v * c;
      sum_y[s] += v * r;
      sum_cos[s] += v * std::cos(2.0 * t);
      sum_sin[s] += v * std::sin(2.0 * t);
      g.anchor_x[s] = c;  // column-major scan: the last write is the anchor
      g.anchor_y[s] = r;
    }
  }
  g.magnitude.assign(n, 0.f);
  g.mean_x.assign(n, 0.f);
  g.mean_y.assign(n, 0.f);
  g.orientation.assign(n, 0.f);
  for (size_t s = 1; s < n; ++s) {
    g.magnitude[s] = static_cast<float>(sum_m[s]);
    g.mean_x[s] = static_cast<float>(sum_x[s] / sum_m[s]);
    g.mean_y[s] = static_cast<float>(sum_y[s] / sum_m[s]);
    g.orientation[s] = static_cast<float>(0.5 * std::atan2(sum_sin[s], sum_cos[s]));
  }
}

void ComputeAffinities(const EdgePixels& edges, const cv::Mat1i& ids, float gamma, EdgeGroups& g) {
  const int n = g.count() + 1;
  std::vector<std::vector<std::pair<int, float>>> neighbours(n);
  constexpr int kRadius = 2;  // 5x5 neighbourhood
  if (!ids.empty()) {
    const GroupingMaps m{&edges, ids.cols, ids.rows, nullptr, nullptr};
    const int* label = ids.ptr<int>(0);
    const int w = ids.cols;
    // Column-major, as the full scan: each neighbour list gets its entries in the same order.
    ForEachInterior(m, kRadius, [&](int, int, int, int p) {
      const int s0 = label[p];
      if (s0 <= 0) return;
      for (int dc = -kRadius; dc <= kRadius; ++dc) {
        for (int dr = -kRadius; dr <= kRadius; ++dr) {
          const int s1 = label[p + dr * w + dc];
          if (s1 <= s0) continue;  // each unordered pair once, from its smaller id
          auto& list = neighbours[s0];
          if (std::any_of(list.begin(), list.end(), [s1](const auto& e) { return e.first == s1; }))
            continue;
          const float phi =
              std::atan2(g.mean_y[s0] - g.mean_y[s1], g.mean_x[s0] - g.mean_x[s1]) + kPi / 2.f;
          const float a = std::pow(
              std::fabs(std::cos(g.orientation[s0] - phi) * std::cos(g.orientation[s1] - phi)),
              gamma);
          list.emplace_back(s1, a);
          neighbours[s1].emplace_back(s0, a);
        }
      }
    });
  }
  g.affinity_begin.assign(static_cast<size_t>(n) + 1, 0);
  for (int s = 0; s < n; ++s) {
    g.affinity_begin[s + 1] = g.affinity_begin[s] + static_cast<int>(neighbours[s].size());
  }
  g.affinity_target.resize(g.affinity_begin[n]);
  g.affinity_value.resize(g.affinity_begin[n]);
  for (int s = 0; s < n; ++s) {
    int k = g.affinity_begin[s];
    for (const auto& [t, a] : neighbours[s]) {
      g.affinity_target[k] = t;
      g.affinity_value[k] = a;
      ++k;
    }
  }
}

bool SameShape(const cv::Mat1f& a, const cv::Mat1f& b) { return a.size() == b.size(); }

// Steps 1-3 from the edge list and an orientation map valid at its interior pixels; no groups
// at all without one.
EdgeGroups BuildFromEdges(EdgePixels edges, const cv::Mat1f* theta, const EdgeGroupParams& params) {
  EdgeGroups g;
  int count = 0;
  if (theta != nullptr) {
    g.ids = GroupPixels(edges, *theta, params, &count);
    ComputeStatistics(edges, g.ids, *theta, count, g);
  } else {
    g.ids = cv::Mat1i(edges.rows, edges.cols, kNoGroup);
    ComputeStatistics(EdgePixels{}, g.ids, cv::Mat1f(), 0, g);
  }
  ComputeAffinities(edges, g.ids, params.gamma, g);
  g.edges = std::move(edges);
  return g;
}

cv::Mat1f Continuous(const cv::Mat1f& m) { return m.isContinuous() ? m : m.clone(); }

}  // namespace

EdgePixels FindEdgePixels(const cv::Mat1f& map, float min_magnitude) {
  EdgePixels e;
  e.rows = map.rows;
  e.cols = map.cols;
  e.row_begin.assign(static_cast<size_t>(e.rows) + 1, 0);
  e.col_begin.assign(static_cast<size_t>(e.cols) + 1, 0);
  for (int r = 0; r < e.rows; ++r) {
    const float* row = map[r];
    const auto take = [&](int c) {
      if (row[c] > min_magnitude) {
        e.row_col.push_back(c);
        e.row_value.push_back(row[c]);
        ++e.col_begin[c + 1];
      }
    };
    // Edge pixels are sparse: a branch-free (vectorised) test skips blocks without any.
    constexpr int kBlock = 16;
    int c = 0;
    for (; c + kBlock <= e.cols; c += kBlock) {
      // The block's largest value (NaN never wins, and is never an edge pixel either).
      float largest = -std::numeric_limits<float>::infinity();
      for (int k = 0; k < kBlock; ++k) largest = row[c + k] > largest ? row[c + k] : largest;
      if (!(largest > min_magnitude)) continue;
      for (int k = 0; k < kBlock; ++k) take(c + k);
    }
    for (; c < e.cols; ++c) take(c);
    e.row_begin[r + 1] = static_cast<int>(e.row_col.size());
  }
  // Counting sort by column; row-major input keeps the rows of each column ascending.
  for (int c = 0; c < e.cols; ++c) e.col_begin[c + 1] += e.col_begin[c];
  e.col_row.resize(e.row_col.size());
  e.col_value.resize(e.row_col.size());
  std::vector<int> next(e.col_begin.begin(), e.col_begin.begin() + e.cols);
  for (int r = 0; r < e.rows; ++r) {
    for (int i = e.row_begin[r]; i < e.row_begin[r + 1]; ++i) {
      const int k = next[e.row_col[i]]++;
      e.col_row[k] = r;
      e.col_value[k] = e.row_value[i];
    }
  }
  return e;
}

cv::Mat1i GroupEdgePixels(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                          const EdgeGroupParams& params) {
  if (edge_map.empty() || !SameShape(edge_map, orientation)) return {};
  int count = 0;
  return GroupPixels(FindEdgePixels(edge_map, params.edge_min_mag), Continuous(orientation), params,
                     &count);
}

EdgeGroups BuildEdgeGroups(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                           const EdgeGroupParams& params) {
  EdgePixels edges = FindEdgePixels(edge_map, params.edge_min_mag);
  if (edge_map.empty() || !SameShape(edge_map, orientation)) {
    return BuildFromEdges(std::move(edges), nullptr, params);
  }
  const cv::Mat1f theta = Continuous(orientation);
  return BuildFromEdges(std::move(edges), &theta, params);
}

EdgeGroups BuildEdgeGroups(const cv::Mat1f& edge_map, const EdgeGroupParams& params) {
  EdgePixels edges = FindEdgePixels(edge_map, params.edge_min_mag);
  // theta only where grouping reads it: at interior edge pixels. The rest of the map stays
  // uninitialised (never read), which also spares writing it.
  cv::Mat1f theta(edge_map.size());
  if (!edge_map.empty()) {
    const cv::Mat1f smoothed = SmoothForOrientation(edge_map);
    for (int c = 1; c < edges.cols - 1; ++c) {
      for (int i = edges.col_begin[c]; i < edges.col_begin[c + 1]; ++i) {
        const int r = edges.col_row[i];
        if (r >= 1 && r < edges.rows - 1) theta(r, c) = OrientationAt(smoothed, r, c);
      }
    }
  }
  return BuildFromEdges(std::move(edges), &theta, params);
}

}  // namespace tod
