// One node of a RandomForest tree as it is trained, saved and loaded (ALGORITHM.md §6.3).
// Kept in its own header so that the prediction layout (compact_forest.h) can be built from it
// without depending on RandomForest itself.
#pragma once

#include <cstdint>

namespace tod {

// 12 bytes per node; the two children of a split are adjacent (right = left + 1), so one index
// suffices, and children always come after their parent (which is what makes a loaded forest
// provably acyclic).
struct ForestNode {
  std::int32_t feature = -1;  // -1 = leaf
  float value = 0.f;          // split: threshold (go left when x[feature] <= value); leaf: mean
  std::int32_t left = -1;     // index of the left child; right child = left + 1
};

}  // namespace tod
