#include "core/evaluation/obstacle_list_sweep.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

// A 100 x 100 frame with two obstacles: A at (10, 10) 20 x 20 and B at (60, 60) 10 x 10.
Sample TwoObstacleFrame() {
  Sample s;
  s.image = cv::Mat3b(100, 100, cv::Vec3b(0, 0, 0));
  s.road = cv::Mat1b(100, 100, uchar{255});
  s.obstacle = cv::Mat1b(100, 100, uchar{0});
  s.ignore = cv::Mat1b(100, 100, uchar{0});
  for (const Box& b : {Box{10, 10, 20, 20}, Box{60, 60, 10, 10}}) {
    s.obstacle(b.rect()).setTo(255);
    s.road(b.rect()).setTo(0);
    s.instances.push_back({static_cast<int>(s.instances.size()), b, cv::Mat1b(b.h, b.w, 255)});
  }
  return s;
}

TEST(ObstacleListSweepTest, CountsMatchesAtBothIousOverlapsAndFalseAlarms) {
  const Sample s = TwoObstacleFrame();
  // On A: box (10, 10) 20 x 10, IoU 200 / 400 = 0.5. Overlapping B: (65, 65) 10 x 10, IoU
  // 25 / 175 = 0.14. On nothing: (80, 0) 5 x 5.
  const ObstacleListCounts c =
      CountObstacleList(s, {Box{10, 10, 20, 10}, Box{65, 65, 10, 10}, Box{80, 0, 5, 5}});
  EXPECT_EQ(c.reported, 3);
  EXPECT_EQ(c.false_alarms, 1);
  EXPECT_EQ(c.instances_found, 2);
  EXPECT_EQ(c.found_iou25, 1);
  EXPECT_EQ(c.found_iou50, 1);

  ObstacleListCounts sum = c;
  sum += CountObstacleList(s, {});
  EXPECT_EQ(sum.instances_found, 2);
  EXPECT_EQ(sum.reported, 3);
}

TEST(ObstacleListSweepTest, BoxListKeepsTheBestOfNestedBoxesAndDropsSmallOrWeakOnes) {
  PipelineParams params;  // no fitted calibration: the score is the fused score itself
  const std::vector<ScoredBox> boxes = {
      {{10, 10, 20, 20}, 0.6f},  // kept
      {{12, 12, 10, 10}, 0.9f},  // kept first: the best
      {{40, 40, 10, 10}, 0.3f},  // below the minimum
      {{70, 70, 3, 3}, 0.95f},   // 9 px, under the minimum area
      {{25, 10, 20, 20}, 0.7f},  // apart from the 0.9 box: kept
  };
  const std::vector<DetectedObstacle> list = BoxListObstacles(boxes, params, 0.5f, 10);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].box, (Box{12, 12, 10, 10}));
  EXPECT_FLOAT_EQ(list[0].score, 0.9f);
  // The 0.6 box holds the 0.9 box entirely: the same object, dropped (the 0.7 box overlaps it by
  // 5 x 20 = 100 px, a quarter, which alone would not drop it).
  EXPECT_EQ(list[1].box, (Box{25, 10, 20, 20}));
}

TEST(ObstacleListSweepTest, JsonNestsRulesAndMinimumScores) {
  std::map<std::string, ObstacleListCounts> sweep;
  sweep["boxes/0.50"] = {4, 1, 2, 2, 1};
  sweep["components@0.50/0.50"] = {2, 0, 1, 1, 1};
  const nlohmann::json j = ObstacleListSweepToJson(sweep, /*instances=*/4, /*frames=*/2);
  EXPECT_DOUBLE_EQ(j["boxes"]["0.50"]["found_iou50"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["boxes"]["0.50"]["found_iou25"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["boxes"]["0.50"]["false_alarms_per_frame"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["components@0.50"]["0.50"]["reported_per_frame"].get<double>(), 1.0);
  EXPECT_NE(FormatObstacleListSweep(sweep, 4, 2).find("components@0.50/0.50"), std::string::npos);
}

}  // namespace
}  // namespace tod
