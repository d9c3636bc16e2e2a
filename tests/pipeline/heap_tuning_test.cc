// RetainLargeAllocations() must take effect: with it a large block that is freed and allocated
// again reuses pages the process already has, instead of faulting in fresh zeroed ones (which is
// what it is for: a frame's per-region tables, allocated and freed every frame).
#include "core/base/heap_tuning.h"

#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <latch>
#include <memory>
#include <semaphore>
#include <thread>

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

#if defined(__GLIBC__) && defined(__linux__)
// The page faults of two threads that live side by side, as two server workers do: each first
// takes its heap (a small allocation), then one touches and frees a block, then the other. With
// an arena per thread the second would fault in all ~6000 pages again. (Threads one after the
// other would not show it: glibc hands an exited thread's arena to the next thread.) Prints
// "first N second M" and exits 0 when the second thread reused the first one's pages.
[[noreturn]] void TwoWorkersTouchOneBlockEach() {
  constexpr std::size_t kBytes = std::size_t{24} << 20;
  long first = 0, second = 0;
  std::latch both_have_a_heap(2);
  std::binary_semaphore first_done(0);
  const auto take_heap = [&] {
    const auto small = std::make_unique<std::array<char, 256>>();
    (*small)[0] = 1;
    both_have_a_heap.arrive_and_wait();
  };
  std::thread a([&] {
    take_heap();
    first = FaultsOfTouchedBlock(kBytes);
    first_done.release();
  });
  std::thread b([&] {
    take_heap();
    first_done.acquire();
    second = FaultsOfTouchedBlock(kBytes);
  });
  a.join();
  b.join();
  std::fprintf(stderr, "first %ld second %ld\n", first, second);
  std::exit(first > 1000 && second < 200 ? 0 : 1);
}
#endif

// ShareOneHeapArena holds for a process that calls it before it starts threads, as tod_server
// does at start-up. Earlier tests of this binary may have started threads that made arenas of
// their own (glibc fixes its arena limit when the first thread allocates), and a thread may then
// be handed one of those, so the check runs in a fresh process: the "threadsafe" death-test style
// re-executes this binary for this test alone. The child prints both fault counts; the first
// block needs fresh pages, the second thread reuses them.
TEST(HeapTuningTest, OneSharedArenaLetsAThreadReuseWhatAnotherFreed) {
  if (std::getenv("MALLOC_ARENA_MAX") != nullptr) GTEST_SKIP() << "the environment sets arenas";
#if defined(__GLIBC__) && defined(__linux__)
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        if (!RetainLargeAllocations() || !ShareOneHeapArena()) std::exit(2);
        TwoWorkersTouchOneBlockEach();
      },
      ::testing::ExitedWithCode(0), "first [0-9]+ second [0-9]+");
#else
  GTEST_SKIP() << "the setting only applies to glibc";
#endif
}

}  // namespace
}  // namespace tod
