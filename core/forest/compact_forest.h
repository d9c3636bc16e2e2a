// The prediction-time form of a RandomForest: the same trees, node for node, packed so that
// batch prediction is fast on one core.
//
// Why it is fast (measured in tests/bench/bench_forest_predict.cc):
//  * 8-byte split nodes (threshold + one word holding feature and left-child index) instead of
//    12: more of a tree fits in cache;
//  * a leaf is a node that points to itself with threshold +inf, so a step never leaves it and
//    the descent needs no leaf test: the inner loop is branch-free;
//  * rows are walked tree-major over blocks (one tree for all rows of a block, so the tree stays
//    in cache) and several rows descend in lock-step, which turns one long chain of dependent
//    loads into independent chains the CPU overlaps;
//  * the rows of a block are first copied side by side at a power-of-two stride that is also the
//    feature field's width, so with that width as a compile-time constant a lane's feature is
//    one load at a constant offset from the group's base: no per-lane row pointer (which left
//    too few registers and was reloaded from the stack on every step) and no variable shifts.
// Per row, leaf values are still added in tree order into a double starting at 0, exactly as
// RandomForest::Predict does, so the results are bit-identical.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/forest/forest_node.h"

namespace tod {

class CompactForest {
 public:
  CompactForest() = default;

  // Packs the trees rooted at `roots` (indices into `nodes`, which must be valid as
  // RandomForest guarantees: children after parents and in range, features < num_features).
  // Node indices are kept, so any node structure (even one shared between trees) packs as is.
  // Gives an empty CompactForest when the indices do not fit the packed word (more than
  // 2^(32 - bits for a feature index) nodes); callers then walk the ForestNodes directly.
  static CompactForest Build(const std::vector<ForestNode>& nodes,
                             const std::vector<std::int32_t>& roots, int num_features);

  bool empty() const { return roots_.empty(); }
  // Bytes a prediction may touch per node: the packed node and its leaf value.
  static constexpr std::size_t bytes_per_node() { return sizeof(PackedNode) + sizeof(float); }

  // For every tree of [tree_begin, tree_end) in order, adds the value of the leaf that rows[k]
  // reaches to sums[k], for k in [0, count). Each row must hold at least num_features values.
  // Going on from tree_end later adds the same values in the same order as one call would.
  void AccumulateLeafValues(const float* const* rows, int count, double* sums, int tree_begin,
                            int tree_end) const;

 private:
  struct PackedNode {
    float threshold = 0.f;   // go to the right child when x > threshold; +inf in a leaf
    std::uint32_t word = 0;  // (left child index << feature_bits_) | feature; leaf: own index
  };
  static_assert(sizeof(PackedNode) == 8);

  // The walk over rows copied to a stride of 2^kFeatureBits floats (see above); kFeatureBits 0
  // reads the width from feature_bits_ (rows of more than 128 features).
  template <int kFeatureBits>
  void AccumulateCopied(const float* const* rows, int count, double* sums, int tree_begin,
                        int tree_end) const;

  int feature_bits_ = 0;
  int num_features_ = 0;
  std::vector<PackedNode> nodes_;
  std::vector<float> leaf_values_;  // per node; meaningful for leaves only
  std::vector<std::uint32_t> roots_;
};

}  // namespace tod
