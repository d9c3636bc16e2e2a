#include "core/proposals/edge_groups.h"

#include <gtest/gtest.h>

#include "core/proposals/edge_orientation.h"

namespace tod {
namespace {

EdgeGroups Build(const cv::Mat1f& map) {
  return BuildEdgeGroups(map, ComputeEdgeOrientation(map), EdgeGroupParams{});
}

TEST(EdgeGroupsTest, StraightLineIsOneGroupAnchoredAtItsLastPixel) {
  // A vertical line is separable after smoothing, so Oxy = 0 on it and every pixel has the same
  // orientation: the walk never accumulates cost and takes the whole line.
  cv::Mat1f map(20, 20, 0.f);
  for (int y = 3; y <= 12; ++y) map(y, 5) = 1.f;
  const EdgeGroups g = Build(map);
  ASSERT_EQ(g.count(), 1);
  for (int y = 3; y <= 12; ++y) EXPECT_EQ(g.ids(y, 5), 1);
  EXPECT_EQ(cv::countNonZero(g.ids), 10);
  EXPECT_FLOAT_EQ(g.magnitude[1], 10.f);
  EXPECT_FLOAT_EQ(g.mean_x[1], 5.f);
  EXPECT_FLOAT_EQ(g.mean_y[1], 7.5f);
  EXPECT_EQ(g.anchor_x[1], 5);  // last in column-major order: bottom pixel
  EXPECT_EQ(g.anchor_y[1], 12);
  EXPECT_EQ(g.affinity_begin.back(), 0);  // nothing to relate to
}

TEST(EdgeGroupsTest, WeakIsolatedGroupIsDissolvedAndBorderIgnored) {
  cv::Mat1f map(20, 20, 0.f);
  for (int y = 3; y <= 12; ++y) map(y, 5) = 1.f;
  map(15, 15) = map(15, 16) = 0.2f;  // magnitude 0.4 <= 0.5, no grouped neighbour
  map(0, 10) = 1.f;                  // border pixels are never edge pixels
  map(8, 12) = 0.05f;                // below edge_min_mag
  const EdgeGroups g = Build(map);
  EXPECT_EQ(g.count(), 1);
  EXPECT_EQ(g.ids(15, 15), 0);
  EXPECT_EQ(g.ids(15, 16), 0);
  EXPECT_EQ(g.ids(0, 10), 0);
  EXPECT_EQ(g.ids(8, 12), 0);
}

TEST(EdgeGroupsTest, WeakPixelsNextToAGroupJoinIt) {
  cv::Mat1f map(20, 20, 0.f);
  for (int y = 3; y <= 12; ++y) map(y, 5) = 1.f;
  // A weak 2-pixel stub continuing the line: if the walk left it out it would be dissolved and
  // handed to the line; either way it ends in the line's group.
  map(13, 5) = map(14, 5) = 0.2f;
  const EdgeGroups g = Build(map);
  ASSERT_EQ(g.count(), 1);
  EXPECT_EQ(g.ids(13, 5), 1);
  EXPECT_EQ(g.ids(14, 5), 1);
}

TEST(EdgeGroupsTest, CollinearNeighbouringGroupsHaveFullAffinity) {
  // Two segments of one vertical line with a 1-pixel gap: separate groups (not 8-adjacent) but
  // within a 5x5 neighbourhood. Means (5, 7.5) and (5, 18.5): phi = atan2(-11, 0) + pi/2 = 0,
  // both orientations 0 -> a = |cos 0 * cos 0|^2 = 1.
  cv::Mat1f map(40, 20, 0.f);
  for (int y = 3; y <= 12; ++y) map(y, 5) = 1.f;
  for (int y = 14; y <= 23; ++y) map(y, 5) = 1.f;
  const EdgeGroups g = Build(map);
  ASSERT_EQ(g.count(), 2);
  ASSERT_EQ(g.affinity_begin[2] - g.affinity_begin[1], 1);
  EXPECT_EQ(g.affinity_target[g.affinity_begin[1]], 2);
  EXPECT_NEAR(g.affinity_value[g.affinity_begin[1]], 1.f, 1e-5f);
  ASSERT_EQ(g.affinity_begin[3] - g.affinity_begin[2], 1);  // symmetric
  EXPECT_EQ(g.affinity_target[g.affinity_begin[2]], 1);

  cv::Mat1f apart(20, 30, 0.f);
  for (int y = 3; y <= 12; ++y) apart(y, 5) = apart(y, 15) = 1.f;
  const EdgeGroups h = Build(apart);
  ASSERT_EQ(h.count(), 2);
  EXPECT_EQ(h.affinity_begin.back(), 0) << "10 px apart: no 5x5 contact, no affinity";
}

TEST(EdgeGroupsTest, EmptyAndTinyMaps) {
  EXPECT_EQ(Build(cv::Mat1f()).count(), 0);
  EXPECT_EQ(Build(cv::Mat1f(1, 1, 1.f)).count(), 0);
  EXPECT_EQ(Build(cv::Mat1f(3, 200, 1.f)).count(), 1);  // the single interior row
  EXPECT_EQ(Build(cv::Mat1f(2, 200, 1.f)).count(), 0);  // no interior at all
}

}  // namespace
}  // namespace tod
