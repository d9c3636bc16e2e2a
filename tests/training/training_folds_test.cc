#include "core/training/training_folds.h"

#include <gtest/gtest.h>

#include <vector>

namespace tod {
namespace {

// The usable frames in order, cut into runs; an unusable position keeps -1 and does not
// count towards the cut.
TEST(AssignFoldsTest, BlocksCutTheUsableFramesIntoConsecutiveRuns) {
  const std::vector<int> usable = {0, 1, 2, 4, 5, 6};  // position 3 was skipped
  const std::vector<int> folds = AssignFolds(7, usable, 2);
  EXPECT_EQ(folds, (std::vector<int>{0, 0, 0, -1, 1, 1, 1}));
  const std::vector<int> three = AssignFolds(7, usable, 3);
  EXPECT_EQ(three, (std::vector<int>{0, 0, 1, -1, 1, 2, 2}));
}

// With several datasets (tod train --add-data), each is cut into runs of its own: one fold per
// dataset would train every copy on one domain only.
TEST(AssignFoldsTest, BlocksCutEachDatasetSeparately) {
  const std::vector<int> usable = {0, 1, 2, 3, 4, 5, 6, 7};
  const std::vector<int> source = {0, 0, 0, 0, 1, 1, 1, 1};
  const std::vector<int> folds = AssignFolds(8, usable, 2, source);
  EXPECT_EQ(folds, (std::vector<int>{0, 0, 1, 1, 0, 0, 1, 1}));
}

// Each block holds half of the classifier frames when they are spread over the split, so both
// fold copies of a classifier have frames to learn from.
TEST(AssignFoldsTest, BlocksSplitSpreadClassifierFramesEvenly) {
  std::vector<int> usable;
  for (int i = 0; i < 35; ++i) usable.push_back(i);
  const std::vector<int> classifier = {0, 5, 10, 15, 20, 25, 30};
  const std::vector<int> folds = AssignFolds(35, usable, 2);
  int in_first = 0;
  for (int i : classifier) in_first += folds[i] == 0;
  EXPECT_EQ(in_first, 4);  // frames 0-17 are fold 0
  EXPECT_EQ(folds[17], 0);
  EXPECT_EQ(folds[18], 1);
}

}  // namespace
}  // namespace tod
