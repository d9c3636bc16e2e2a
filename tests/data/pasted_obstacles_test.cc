#include "core/data/pasted_obstacles.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <vector>

namespace tod {
namespace {

// A grey road frame of `width` x `height` (free space everywhere but a void band at the bottom)
// with one dark square obstacle of side `side` at (x, y) and a lighter contact shadow under it.
Sample RoadFrame(int width, int height, int x, int y, int side, unsigned char road_grey = 120) {
  Sample s;
  s.name = "frame";
  s.image = cv::Mat3b(height, width, cv::Vec3b(road_grey, road_grey, road_grey));
  s.road = cv::Mat1b(height, width, 255);
  s.obstacle = cv::Mat1b::zeros(height, width);
  s.ignore = cv::Mat1b::zeros(height, width);
  s.ignore.rowRange(height - 4, height).setTo(255);
  s.road.rowRange(height - 4, height).setTo(0);
  if (side > 0) {
    const Box box{x, y, side, side};
    s.image(cv::Rect(x, y + side, side, 2)).setTo(cv::Vec3b(90, 90, 90));  // shadow
    s.image(box.rect()).setTo(cv::Vec3b(20, 40, 200));
    s.obstacle(box.rect()).setTo(255);
    s.road(box.rect()).setTo(0);
    s.instances.push_back({7, box, cv::Mat1b(side, side, 255)});
  }
  return s;
}

// The cut-out of a 12-pixel obstacle at (x, 40) of a road frame `width` wide.
ObstacleCutout SquareCutout(int width, int x) {
  const Sample donor = RoadFrame(width, 100, x, 40, 12);
  return CutOutObstacle(donor, donor.instances[0], 1, {});
}

TEST(PastedObstacles, CutOutCarriesItsRingFeathered) {
  const Sample s = RoadFrame(200, 100, 50, 40, 12);
  const PasteParams params;  // ring: 0.25 * 12 = 3 pixels
  const ObstacleCutout c = CutOutObstacle(s, s.instances[0], 4, params);
  ASSERT_FALSE(c.patch.empty());
  EXPECT_EQ(c.frame, 4);
  EXPECT_EQ(c.box, (Box{47, 37, 18, 18}));
  EXPECT_EQ(cv::countNonZero(c.mask), 144);
  EXPECT_FLOAT_EQ(c.alpha(9, 9), 1.f);  // on the obstacle
  EXPECT_FLOAT_EQ(c.alpha(0, 0), 0.f);  // the ring's far corner
  EXPECT_GT(c.alpha(9, 1), 0.f);        // inside the ring, two pixels off the obstacle
  EXPECT_LT(c.alpha(9, 1), 1.f);
  EXPECT_EQ(c.patch(16, 9), cv::Vec3b(90, 90, 90));  // the shadow comes along
}

TEST(PastedObstacles, NoCutOutWhenItsRingMeetsVoidOrAnotherObstacle) {
  const Sample near_void = RoadFrame(200, 100, 50, 84, 12);  // ring reaches the void rows
  EXPECT_TRUE(CutOutObstacle(near_void, near_void.instances[0], 0, {}).patch.empty());
  Sample pair = RoadFrame(200, 100, 50, 40, 12);
  pair.obstacle(cv::Rect(63, 40, 4, 4)).setTo(255);
  pair.road(cv::Rect(63, 40, 4, 4)).setTo(0);
  EXPECT_TRUE(CutOutObstacle(pair, pair.instances[0], 0, {}).patch.empty());
}

TEST(PastedObstacles, PastedAtItsRowOnFreeSpaceAndLabelled) {
  const ObstacleCutout c = SquareCutout(400, 100);
  const Sample target = RoadFrame(400, 100, 300, 20, 10);
  PasteParams params;
  params.obstacles_per_frame = 1;
  const Sample pasted = PasteObstacles(target, {&c}, 42, params);
  ASSERT_EQ(pasted.instances.size(), 2u);
  const ObstacleInstance& added = pasted.instances[1];
  EXPECT_EQ(added.box.y, 40);  // its own row
  EXPECT_EQ(added.box.w, 12);
  EXPECT_LE(std::abs(added.box.x - 100), static_cast<int>(0.2 * 400));
  EXPECT_EQ(cv::countNonZero(pasted.obstacle(added.box.rect())), 144);
  EXPECT_EQ(cv::countNonZero(pasted.road(added.box.rect())), 0);
  EXPECT_EQ(pasted.image(added.box.y + 5, added.box.x + 5), cv::Vec3b(20, 40, 200));
  // The target is untouched, and the same seed places the same way.
  EXPECT_EQ(target.instances.size(), 1u);
  EXPECT_EQ(cv::countNonZero(target.obstacle), 100);
  const Sample again = PasteObstacles(target, {&c}, 42, params);
  EXPECT_EQ(again.instances[1].box, added.box);
  EXPECT_EQ(cv::norm(again.image, pasted.image, cv::NORM_INF), 0.0);
}

TEST(PastedObstacles, NeverOnAnotherSurface) {
  const ObstacleCutout c = SquareCutout(400, 100);
  // Free space everywhere, but another surface: a bright wall, a busy hedge or car. The ring
  // would not match either.
  const Sample wall = PasteObstacles(RoadFrame(400, 100, 0, 0, 0, /*road_grey=*/230), {&c}, 3, {});
  EXPECT_TRUE(wall.instances.empty());
  Sample busy = RoadFrame(400, 100, 0, 0, 0);
  cv::randu(busy.image, 0, 256);
  const Sample pasted = PasteObstacles(busy, {&c}, 3, {});
  EXPECT_TRUE(pasted.instances.empty());
  EXPECT_EQ(cv::countNonZero(pasted.obstacle), 0);
}

TEST(PastedObstacles, NeverOverObstaclesVoidOrEachOther) {
  const ObstacleCutout c = SquareCutout(120, 50);
  // The target's own obstacle fills most of the row band the cut-out may go to.
  const Sample target = RoadFrame(120, 100, 20, 30, 40);
  PasteParams params;
  params.obstacles_per_frame = 4;
  params.tries = 200;
  const Sample pasted = PasteObstacles(target, {&c, &c, &c, &c}, 5, params);
  cv::Mat1b covered = cv::Mat1b::zeros(target.image.size());
  for (std::size_t k = 1; k < pasted.instances.size(); ++k) {
    const Box b = pasted.instances[k].box;
    // A square's footprint (alpha > 0: less than 3 pixels off it) is its box grown by 2.
    const Box ring{b.x - 2, b.y - 2, b.w + 4, b.h + 4};
    EXPECT_EQ(cv::countNonZero(target.obstacle(ring.rect())), 0);
    EXPECT_EQ(cv::countNonZero(covered(ring.rect())), 0);
    covered(ring.rect()).setTo(255);
  }
  EXPECT_GE(pasted.instances.size(), 2u);  // room for one at least, beside the obstacle
}

TEST(PastedObstacles, OwnObstaclesVoidedLeaveThePastedOnes) {
  const ObstacleCutout c = SquareCutout(400, 100);
  const Sample target = RoadFrame(400, 100, 300, 20, 10);
  Sample pasted = PasteObstacles(target, {&c}, 42, {});
  ASSERT_EQ(pasted.instances.size(), 2u);
  const Box added = pasted.instances[1].box;
  VoidOwnObstacles(pasted, 1);
  ASSERT_EQ(pasted.instances.size(), 1u);
  EXPECT_EQ(pasted.instances[0].box, added);
  EXPECT_EQ(cv::countNonZero(pasted.obstacle), 144);  // the pasted obstacle only
  EXPECT_EQ(cv::countNonZero(pasted.ignore(cv::Rect(300, 20, 10, 10))), 100);
  EXPECT_EQ(cv::countNonZero(target.ignore(cv::Rect(300, 20, 10, 10))), 0);  // a copy's own
}

}  // namespace
}  // namespace tod
