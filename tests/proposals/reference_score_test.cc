// Checks the optimised scorer (integral images, run indexes, queue walk, early stops) against a
// direct transcription of ALGORITHM.md §4.2.4 on random boxes of a random contour map.
#include "tests/proposals/reference_score.h"

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

using testing::ReferenceScore;

EdgeGroups GroupsOf(const cv::Mat1f& map, const EdgeBoxParams& params) {
  const EdgeGroupParams gp{params.edge_min_mag, params.edge_merge_thr, params.cluster_min_mag,
                           params.gamma};
  return BuildEdgeGroups(map, ComputeEdgeOrientation(map), gp);
}

// Scores `trials` random boxes of the map with the optimised scorer and the literal definition
// (equal up to the order of floating-point summation); returns how many score above 0.
int CompareRandomBoxes(const cv::Mat1f& map, const EdgeGroups& groups, const EdgeBoxParams& params,
                       std::mt19937& rng, int trials) {
  std::uniform_int_distribution<int> cx(0, map.cols - 1), ry(0, map.rows - 1);
  int nonzero = 0;
  for (int trial = 0; trial < trials; ++trial) {
    int c0 = cx(rng), c1 = cx(rng), r0 = ry(rng), r1 = ry(rng);
    if (c0 > c1) std::swap(c0, c1);
    if (r0 > r1) std::swap(r0, r1);
    const float expected = ReferenceScore(map, groups, r0, c0, r1, c1, params);
    const float got = ScoreSingleBox(map, Box{c0, r0, c1 - c0 + 1, r1 - r0 + 1}, params);
    EXPECT_NEAR(got, expected, 1e-5f + 1e-5f * expected)
        << c0 << "," << r0 << "," << c1 << "," << r1;
    nonzero += expected > 0.f;
  }
  return nonzero;
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
  const EdgeGroups groups = GroupsOf(map, params);
  ASSERT_GT(groups.count(), 20);
  const int nonzero = CompareRandomBoxes(map, groups, params, rng, 600);
  EXPECT_GT(nonzero, 20);  // the comparison covers the walk, not only early exits
}

// Rows and columns crossing more runs than the scorer scans (16): its search by halves must find
// the same first run as a scan. A lattice of small squares crosses ~27 runs a line.
TEST(ReferenceScoreTest, DenseLinesAgreeWithTheLiteralDefinition) {
  cv::Mat1f map(120, 160, 0.f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> mag(0.2f, 1.f);
  for (int y = 2; y + 4 < map.rows; y += 6)
    for (int x = 2; x + 4 < map.cols; x += 6)
      cv::rectangle(map, cv::Rect(x, y, 4, 4), cv::Scalar(mag(rng)));
  map = NormaliseToMax(map);
  const EdgeBoxParams params;
  const EdgeGroups groups = GroupsOf(map, params);
  // How many runs of one group the longest row holds.
  int most_runs = 0;
  for (int r = 0; r < map.rows; ++r) {
    int runs = 0;
    for (int c = 0; c < map.cols; ++c) {
      const int id = groups.ids(r, c);
      runs += id > 0 && (c == 0 || groups.ids(r, c - 1) != id);
    }
    most_runs = std::max(most_runs, runs);
  }
  ASSERT_GT(most_runs, 16);
  const int nonzero = CompareRandomBoxes(map, groups, params, rng, 300);
  EXPECT_GT(nonzero, 20);
}

}  // namespace
}  // namespace tod
