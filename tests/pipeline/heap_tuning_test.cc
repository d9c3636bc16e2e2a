// RetainLargeAllocations() is accepted by the C library and leaves allocation working: a block
// above glibc's default mmap threshold is freed and allocated again without error.
#include "core/base/heap_tuning.h"

#include <gtest/gtest.h>

#include <vector>

namespace tod {
namespace {

TEST(HeapTuningTest, SettingIsAcceptedAndLargeBlocksStillAllocate) {
  EXPECT_TRUE(RetainLargeAllocations());
  for (int round = 0; round < 3; ++round) {
    std::vector<double> table(4 << 20, 1.0);  // 32 MB, as a frame's largest tables
    EXPECT_EQ(table.back(), 1.0);
  }
}

}  // namespace
}  // namespace tod
