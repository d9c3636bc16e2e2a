#include "core/base/heap_tuning.h"

// <cstdlib> first: __GLIBC__ is defined by the C library's own headers, so testing it before any
// of them is included (as this file once did) silently compiles the setting out.
#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace tod {
namespace {
bool heap_arena_shared = false;  // set once in main(), before any thread starts
}  // namespace

bool RetainLargeAllocations() {
#if defined(__GLIBC__)
  // 32 MiB is glibc's largest mmap threshold on 64-bit (HEAP_MAX_SIZE / 2): every per-region
  // table of a 2048-wide frame is below it. The trim threshold keeps freed heap tops.
  constexpr int kMmapThreshold = 32 * 1024 * 1024;
  constexpr int kTrimThreshold = 1024 * 1024 * 1024;
  return mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1 &&
         mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1;
#else
  return true;
#endif
}

bool ShareOneHeapArena() {
#if defined(__GLIBC__)
  if (std::getenv("MALLOC_ARENA_MAX") != nullptr) return false;  // the operator's choice
  heap_arena_shared = mallopt(M_ARENA_MAX, 1) == 1;
  return heap_arena_shared;
#else
  return false;
#endif
}

void ReleaseFreeHeapPages() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

bool HeapArenaShared() { return heap_arena_shared; }

}  // namespace tod
