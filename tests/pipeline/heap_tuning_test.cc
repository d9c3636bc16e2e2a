// RetainLargeAllocations() must take effect: with it a large block that is freed and allocated
// again reuses pages the process already has, instead of faulting in fresh zeroed ones (which is
// what it is for: a frame's per-region tables, allocated and freed every frame).
#include "core/base/heap_tuning.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdlib>
#include <memory>

#if defined(__GLIBC__) && defined(__linux__)
#include <sys/resource.h>
#endif

namespace tod {
namespace {

#if defined(__GLIBC__) && defined(__linux__)
long MinorFaults() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt;
}

// Allocates, touches every page of and frees a block of `bytes`; returns the minor page faults
// that took.
long FaultsOfTouchedBlock(std::size_t bytes) {
  const long before = MinorFaults();
  {
    const auto block = std::make_unique_for_overwrite<char[]>(bytes);
    for (std::size_t i = 0; i < bytes; i += 4096) block[i] = static_cast<char>(i);
    EXPECT_EQ(block[4096], static_cast<char>(4096));
  }
  return MinorFaults() - before;
}
#endif

TEST(HeapTuningTest, FreedLargeBlocksAreReusedWithoutPageFaults) {
  ASSERT_TRUE(RetainLargeAllocations());
#if defined(__GLIBC__) && defined(__linux__)
  constexpr std::size_t kBytes = std::size_t{24} << 20;  // like a frame's largest tables
  FaultsOfTouchedBlock(kBytes);                          // the first time pages are new
  const long again = FaultsOfTouchedBlock(kBytes);
  // Without the setting glibc maps and unmaps such a block: ~6000 faults every time.
  EXPECT_LT(again, 200) << "freed block was returned to the kernel";
#else
  GTEST_SKIP() << "the setting only applies to glibc";
#endif
}

}  // namespace
}  // namespace tod
