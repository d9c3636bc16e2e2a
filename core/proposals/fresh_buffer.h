// Sizing of the large per-map tables (several MB each, rebuilt for every region of every frame).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace tod {

// Asks the kernel to back the 2 MB-aligned part of [data, data + bytes) with transparent huge
// pages (where the system allows it on request, THP "madvise" mode): a fresh table is otherwise
// faulted in 4 KB page by page, which costs more than computing it. Only how memory is mapped
// changes, never its contents. No-op elsewhere or for small buffers.
inline void AdviseHugePages(void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr size_t kHuge = size_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHuge - 1);
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

// Large tables are built line by line (column by column): reserve the whole table once, then
// append each line with Append, which zero-fills only that line (a few KB, still in cache when
// the line is computed right after) instead of the whole table up front. A table that is first
// zero-filled in one pass and then computed in a second pass is written twice and read back from
// memory once.
template <typename T>
void ReserveFresh(std::vector<T>& v, size_t n) {
  v.clear();
  v.shrink_to_fit();
  v.reserve(n);
  AdviseHugePages(v.data(), n * sizeof(T));
}

// Appends `count` value-initialised elements (within the reserved capacity: no reallocation, so
// pointers to earlier lines stay valid) and returns a pointer to the first of them.
template <typename T>
T* Append(std::vector<T>& v, size_t count) {
  v.resize(v.size() + count);
  return v.data() + (v.size() - count);
}

}  // namespace tod
