#include "core/proposals/edge_groups.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tod {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr int kNoGroup = 0;
constexpr int kNotEdge = -1;

// Orientation difference of two pixels folded into [0, 0.5] (§4.2.1).
float OrientationCost(float a, float b) {
  const float v = std::fabs(a - b) / kPi;
  return v > 0.5f ? 1.f - v : v;
}

// Everything below works on column-major copies (index c * h + r) because the grouping, the
// dissolution sweeps and the anchor definition are all column-major (§4.2.1-2).
struct ColumnMajorMaps {
  int w = 0, h = 0;
  std::vector<float> mag, theta;
  std::vector<int> label;  // kNotEdge, kNoGroup (unassigned) or a group id
};

ColumnMajorMaps MakeColumnMajor(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                                float edge_min_mag) {
  ColumnMajorMaps m;
  m.w = edge_map.cols;
  m.h = edge_map.rows;
  const size_t n = static_cast<size_t>(m.w) * m.h;
  m.mag.resize(n);
  m.theta.resize(n);
  m.label.assign(n, kNotEdge);
  for (int r = 0; r < m.h; ++r) {
    const float* e = edge_map[r];
    const float* o = orientation[r];
    for (int c = 0; c < m.w; ++c) {
      const size_t p = static_cast<size_t>(c) * m.h + r;
      m.mag[p] = e[c];
      m.theta[p] = o[c];
      // The 1-pixel map border never holds edge pixels, so 8-neighbour look-ups from interior
      // pixels never leave the map.
      const bool interior = r > 0 && c > 0 && r < m.h - 1 && c < m.w - 1;
      if (interior && e[c] > edge_min_mag) m.label[p] = kNoGroup;
    }
  }
  return m;
}

struct Candidate {
  int pixel;
  float cost;
};

// Greedy walk of §4.2.1: the candidate list persists across steps (the walk can branch) and
// is compacted in order while searching for its minimum, which keeps "first minimum wins".
int GreedyGrouping(ColumnMajorMaps& m, float merge_thr) {
  const int h = m.h;
  int next_id = 1;
  std::vector<Candidate> candidates;
  for (int c = 1; c < m.w - 1; ++c) {
    for (int r = 1; r < h - 1; ++r) {
      int current = c * h + r;
      if (m.label[current] != kNoGroup) continue;
      candidates.clear();
      float accumulated = 0.f;
      while (accumulated < merge_thr) {
        m.label[current] = next_id;
        const float theta0 = m.theta[current];
        for (int dc = -1; dc <= 1; ++dc) {
          for (int dr = -1; dr <= 1; ++dr) {
            const int q = current + dc * h + dr;
            if (m.label[q] != kNoGroup) continue;
            candidates.push_back({q, OrientationCost(m.theta[q], theta0)});
          }
        }
        int best = -1;
        size_t live = 0;
        for (size_t k = 0; k < candidates.size(); ++k) {
          if (m.label[candidates[k].pixel] != kNoGroup) continue;  // taken meanwhile: drop
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
    }
  }
  return next_id;
}

// Dissolves groups with magnitude sum <= min_mag and hands their pixels, sweep after sweep,
// to the 8-neighbour group whose pixel has the most similar orientation.
void DissolveWeakGroups(ColumnMajorMaps& m, int id_end, float min_mag) {
  std::vector<double> group_mag(id_end, 0.0);
  const size_t n = m.label.size();
  for (size_t p = 0; p < n; ++p) {
    if (m.label[p] > 0) group_mag[m.label[p]] += m.mag[p];
  }
  std::vector<int> pending;  // column-major order, as the full sweep would visit them
  for (size_t p = 0; p < n; ++p) {
    if (m.label[p] > 0 && group_mag[m.label[p]] <= min_mag) {
      m.label[p] = kNoGroup;
      pending.push_back(static_cast<int>(p));
    }
  }
  const int h = m.h;
  bool changed = true;
  while (changed && !pending.empty()) {
    changed = false;
    size_t still_pending = 0;
    for (const int p : pending) {
      float best_cost = 1000.f;
      int best_label = kNoGroup;
      for (int dc = -1; dc <= 1; ++dc) {
        for (int dr = -1; dr <= 1; ++dr) {
          const int q = p + dc * h + dr;
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

// Relabels surviving groups 1..N in order of their old id; returns N.
int Compact(ColumnMajorMaps& m, int id_end) {
  std::vector<int> new_id(id_end, 0);
  for (const int l : m.label) {
    if (l > 0) new_id[l] = 1;
  }
  int count = 0;
  for (int i = 1; i < id_end; ++i) {
    if (new_id[i]) new_id[i] = ++count;
  }
  for (int& l : m.label) l = l > 0 ? new_id[l] : kNoGroup;
  return count;
}

ColumnMajorMaps GroupColumnMajor(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                                 const EdgeGroupParams& params, int* count) {
  ColumnMajorMaps m = MakeColumnMajor(edge_map, orientation, params.edge_min_mag);
  const int id_end = GreedyGrouping(m, params.edge_merge_thr);
  DissolveWeakGroups(m, id_end, params.cluster_min_mag);
  *count = Compact(m, id_end);
  return m;
}

cv::Mat1i ToRowMajor(const ColumnMajorMaps& m) {
  cv::Mat1i ids(m.h, m.w);
  for (int r = 0; r < m.h; ++r) {
    for (int c = 0; c < m.w; ++c) ids(r, c) = m.label[static_cast<size_t>(c) * m.h + r];
  }
  return ids;
}

void ComputeStatistics(const ColumnMajorMaps& m, int count, EdgeGroups& g) {
  const size_t n = static_cast<size_t>(count) + 1;
  std::vector<double> sum_m(n, 0.0), sum_x(n, 0.0), sum_y(n, 0.0), sum_cos(n, 0.0), sum_sin(n, 0.0);
  g.anchor_x.assign(n, 0);
  g.anchor_y.assign(n, 0);
  for (int c = 0; c < m.w; ++c) {
    for (int r = 0; r < m.h; ++r) {
      const size_t p = static_cast<size_t>(c) * m.h + r;
      const int s = m.label[p];
      if (s <= 0) continue;
      const double v = m.mag[p];
      sum_m[s] += v;
      sum_x[s] += v * c;
      sum_y[s] += v * r;
      sum_cos[s] += v * std::cos(2.0 * m.theta[p]);
      sum_sin[s] += v * std::sin(2.0 * m.theta[p]);
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

void ComputeAffinities(const ColumnMajorMaps& m, float gamma, EdgeGroups& g) {
  const int n = g.count() + 1;
  std::vector<std::vector<std::pair<int, float>>> neighbours(n);
  constexpr int kRadius = 2;  // 5x5 neighbourhood
  const int h = m.h;
  for (int c = kRadius; c < m.w - kRadius; ++c) {
    for (int r = kRadius; r < h - kRadius; ++r) {
      const int s0 = m.label[static_cast<size_t>(c) * h + r];
      if (s0 <= 0) continue;
      for (int dc = -kRadius; dc <= kRadius; ++dc) {
        for (int dr = -kRadius; dr <= kRadius; ++dr) {
          const int s1 = m.label[static_cast<size_t>(c + dc) * h + r + dr];
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
    }
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

}  // namespace

cv::Mat1i GroupEdgePixels(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                          const EdgeGroupParams& params) {
  if (edge_map.empty() || !SameShape(edge_map, orientation)) return {};
  int count = 0;
  return ToRowMajor(GroupColumnMajor(edge_map, orientation, params, &count));
}

EdgeGroups BuildEdgeGroups(const cv::Mat1f& edge_map, const cv::Mat1f& orientation,
                           const EdgeGroupParams& params) {
  EdgeGroups g;
  int count = 0;
  ColumnMajorMaps m;  // no groups at all for an empty map or mismatched shapes
  if (!edge_map.empty() && SameShape(edge_map, orientation)) {
    m = GroupColumnMajor(edge_map, orientation, params, &count);
  }
  g.ids = m.label.empty() ? cv::Mat1i(edge_map.size(), kNoGroup) : ToRowMajor(m);
  ComputeStatistics(m, count, g);
  ComputeAffinities(m, params.gamma, g);
  return g;
}

}  // namespace tod
