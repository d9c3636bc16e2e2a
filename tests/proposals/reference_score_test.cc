// Checks the optimised scorer (integral images, run indexes, queue walk, early stops) against a
// direct transcription of ALGORITHM.md §4.2.4 on random boxes of a random contour map.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/edge_groups.h"
#include "core/proposals/edge_orientation.h"

namespace tod {
namespace {

// Score of the inclusive box [c0, c1] x [r0, r1] computed the slow, literal way: sums by pixel
// loops, boundary groups by scanning the four sides, and the list walk with restarts.
float ReferenceScore(const cv::Mat1f& map, const EdgeGroups& g, int r0, int c0, int r1, int c1,
                     const EdgeBoxParams& p) {
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
  if (bw + bh == 0) return 0.f;
  const float norm = std::pow(1.f / static_cast<float>(bw + bh), p.kappa);
  if (v * norm < p.min_score) return 0.f;
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
  const float score = static_cast<float>(v) * norm;
  return score < p.min_score ? 0.f : score;
}

TEST(ReferenceScoreTest, OptimisedScorerMatchesLiteralDefinition) {
  std::mt19937 rng(11);
  cv::Mat1f map(120, 160, 0.f);
  std::uniform_int_distribution<int> x(5, 150), y(5, 110), rad(4, 25);
  std::uniform_real_distribution<float> mag(0.05f, 1.f);
  for (int i = 0; i < 14; ++i) {
    cv::circle(map, {x(rng), y(rng)}, rad(rng), cv::Scalar(mag(rng)));
    cv::rectangle(map, cv::Rect(x(rng), y(rng), rad(rng), rad(rng)), cv::Scalar(mag(rng)));
  }
  cv::line(map, {0, 60}, {159, 75}, cv::Scalar(0.9f));
  map = NormaliseToMax(map);
  const EdgeBoxParams params;
  const EdgeGroupParams gp{params.edge_min_mag, params.edge_merge_thr, params.cluster_min_mag,
                           params.gamma};
  const EdgeGroups groups = BuildEdgeGroups(map, ComputeEdgeOrientation(map), gp);
  ASSERT_GT(groups.count(), 20);
  std::uniform_int_distribution<int> cx(0, 159), ry(0, 119);
  int nonzero = 0;
  for (int trial = 0; trial < 600; ++trial) {
    int c0 = cx(rng), c1 = cx(rng), r0 = ry(rng), r1 = ry(rng);
    if (c0 > c1) std::swap(c0, c1);
    if (r0 > r1) std::swap(r0, r1);
    const float expected = ReferenceScore(map, groups, r0, c0, r1, c1, params);
    const float got = ScoreSingleBox(map, Box{c0, r0, c1 - c0 + 1, r1 - r0 + 1}, params);
    // Equal up to the order of floating-point summation.
    EXPECT_NEAR(got, expected, 1e-5f + 1e-5f * expected)
        << c0 << "," << r0 << "," << c1 << "," << r1;
    nonzero += expected > 0.f;
  }
  EXPECT_GT(nonzero, 20);  // the comparison covers the walk, not only early exits
}

}  // namespace
}  // namespace tod
