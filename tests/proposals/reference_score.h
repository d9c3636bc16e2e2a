// A direct transcription of the Edge Boxes box score (ALGORITHM.md §4.2.4) for checking the
// optimised scorer: sums by pixel loops, boundary groups by scanning the four sides, and the list
// walk with restarts.
#pragma once

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/edge_groups.h"

namespace tod::testing {

// v - removed of the inclusive box [c0, c1] x [r0, r1]: the group magnitude anchored inside minus
// the centre-box edges minus the walk's weighted magnitudes, before normalisation and threshold.
inline double ReferenceRemainder(const cv::Mat1f& map, const EdgeGroups& g, int r0, int c0, int r1,
                                 int c1, const EdgeBoxParams& p) {
  const auto inside = [&](int s) {
    return g.anchor_x[s] >= c0 && g.anchor_x[s] <= c1 && g.anchor_y[s] >= r0 && g.anchor_y[s] <= r1;
  };
  double v = 0.0;
  for (int s = 1; s <= g.count(); ++s) {
    if (inside(s)) v += g.magnitude[s];
  }
  const int bh = (r1 - r0) / 2, bw = (c1 - c0) / 2;
  const int r0m = r0 + bh / 2, c0m = c0 + bw / 2;
  for (int r = r0m; r <= r0m + bh; ++r) {
    for (int c = c0m; c <= c0m + bw; ++c) {
      if (map(r, c) > p.edge_min_mag) v -= map(r, c);
    }
  }
  std::vector<int> ids;
  std::vector<float> weights;
  const auto add_side_pixel = [&](int r, int c) {
    const int s = g.ids(r, c);
    if (s > 0 && std::find(ids.begin(), ids.end(), s) == ids.end()) {
      ids.push_back(s);
      weights.push_back(1.f);
    }
  };
  for (int c = c0; c <= c1; ++c) add_side_pixel(r0, c), add_side_pixel(r1, c);
  for (int r = r0; r <= r1; ++r) add_side_pixel(r, c0), add_side_pixel(r, c1);
  for (int i = 0; i < static_cast<int>(ids.size()); ++i) {
    const float w = weights[i];
    const int s = ids[i];
    for (int k = g.affinity_begin[s]; k < g.affinity_begin[s + 1]; ++k) {
      const int t = g.affinity_target[k];
      const float wt = w * g.affinity_value[k];
      if (wt < 0.05f) continue;
      const auto it = std::find(ids.begin(), ids.end(), t);
      if (it != ids.end()) {
        const int slot = static_cast<int>(it - ids.begin());
        if (wt > weights[slot]) {
          weights[slot] = wt;
          i = std::min(i, slot - 1);
        }
      } else if (inside(t)) {
        ids.push_back(t);
        weights.push_back(wt);
      }
    }
  }
  for (size_t i = 0; i < ids.size(); ++i) {
    if (inside(ids[i])) v -= weights[i] * g.magnitude[ids[i]];
  }
  return v;
}

// The score: remainder times (bw + bh)^-kappa, 0 below min_score or without an inner part.
inline float ReferenceScore(const cv::Mat1f& map, const EdgeGroups& g, int r0, int c0, int r1,
                            int c1, const EdgeBoxParams& p) {
  const int bh = (r1 - r0) / 2, bw = (c1 - c0) / 2;
  if (bw + bh == 0) return 0.f;
  const float norm = std::pow(1.f / static_cast<float>(bw + bh), p.kappa);
  const float score = static_cast<float>(ReferenceRemainder(map, g, r0, c0, r1, c1, p)) * norm;
  return score < p.min_score ? 0.f : score;
}

}  // namespace tod::testing
