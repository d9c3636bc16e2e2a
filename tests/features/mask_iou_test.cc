#include "core/features/mask_iou.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

// Instance at (2, 3), 4 wide, 3 high, with 7 mask pixels:
//   . X X .
//   X X X X
//   . X . .
ObstacleInstance PlusShapedInstance() {
  ObstacleInstance instance;
  instance.id = 1001;
  instance.box = {2, 3, 4, 3};
  instance.mask = cv::Mat1b(3, 4, uchar{0});
  instance.mask(0, 1) = instance.mask(0, 2) = 255;
  instance.mask.row(1).setTo(255);
  instance.mask(2, 1) = 255;
  return instance;
}

TEST(MaskPixelCounterTest, CountsWithOriginAndClipping) {
  cv::Mat1b mask(4, 5, uchar{0});
  mask.colRange(1, 3).setTo(255);  // columns 1-2 of every row: 8 pixels
  const MaskPixelCounter counter(mask, {10, 20});
  EXPECT_EQ(counter.total(), 8);
  EXPECT_EQ(counter.Count({10, 20, 5, 4}), 8);
  EXPECT_EQ(counter.Count({11, 20, 1, 2}), 2);
  EXPECT_EQ(counter.Count({0, 0, 12, 22}), 2);   // overlaps the mask at column 1, rows 0-1
  EXPECT_EQ(counter.Count({0, 0, 10, 100}), 0);  // left of the mask
  EXPECT_EQ(counter.Count({11, 21, -3, 2}), 0);  // malformed box counts nothing
  EXPECT_EQ(MaskPixelCounter().Count({0, 0, 10, 10}), 0);
}

TEST(MaskIoUTableTest, MatchesHandCount) {
  auto table = MaskIoUTable::Build({PlusShapedInstance()});
  ASSERT_TRUE(table.ok());
  // Box columns 3-4, rows 3-4 covers mask (0,1), (0,2), (1,1), (1,2): 4 pixels; |b| = 4.
  EXPECT_EQ(table->Intersection({3, 3, 2, 2}, 0), 4);
  EXPECT_DOUBLE_EQ(table->IoU({3, 3, 2, 2}, 0), 4.0 / (7 + 4 - 4));
  // Instance box itself: 7 / (7 + 12 - 7).
  EXPECT_DOUBLE_EQ(table->IoU({2, 3, 4, 3}, 0), 7.0 / 12.0);
  // Big box holding the whole mask: 7 / (7 + 100 - 7).
  EXPECT_DOUBLE_EQ(table->IoU({0, 0, 10, 10}, 0), 7.0 / 100.0);
  EXPECT_DOUBLE_EQ(table->IoU({20, 20, 3, 3}, 0), 0.0);
  EXPECT_DOUBLE_EQ(table->MaxBoxIoU({2, 3, 4, 3}), 1.0);
}

TEST(MaskIoUTableTest, MaxOverInstances) {
  ObstacleInstance square;
  square.id = 2001;
  square.box = {20, 20, 2, 2};
  square.mask = cv::Mat1b(2, 2, uchar{255});
  auto table = MaskIoUTable::Build({PlusShapedInstance(), square});
  ASSERT_TRUE(table.ok());
  EXPECT_EQ(table->num_instances(), 2);
  EXPECT_DOUBLE_EQ(table->MaxIoU({20, 20, 2, 2}), 1.0);
  EXPECT_DOUBLE_EQ(table->MaxIoU({3, 3, 2, 2}), 4.0 / 7.0);
  // Box spanning both: instance 1 gives 7/(7+400-7), square 4/(4+400-4) -> the first.
  EXPECT_DOUBLE_EQ(table->MaxIoU({0, 0, 25, 16}), 7.0 / 400.0);
  EXPECT_DOUBLE_EQ(MaskIoUTable().MaxIoU({0, 0, 5, 5}), 0.0);
}

TEST(MaskIoUTableTest, MaskOfWrongSizeIsAnError) {
  ObstacleInstance bad = PlusShapedInstance();
  bad.mask = cv::Mat1b(2, 4, uchar{255});
  auto table = MaskIoUTable::Build({bad});
  ASSERT_FALSE(table.ok());
  EXPECT_NE(table.status().message().find("instance 1001"), std::string::npos);
}

}  // namespace
}  // namespace tod
