#include "core/forest/compact_forest.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <memory>

namespace tod {
namespace {

// Rows descending one tree in lock-step. Enough independent chains to cover the latency of a
// node load, few enough that the lane state stays in registers: with the rows copied to a fixed
// stride a lane needs one register, and 12 lanes beat 8 (regression stage 209-215 -> 194-200 ms
// a frame, bench_pipeline_frame side by side); 14 and 16 were no better.
constexpr int kLanes = 12;
// Steps between tests for "all lanes reached a leaf" (3 measured slightly better than 4 with 12
// lanes, 8 worse).
constexpr int kStepsPerCheck = 3;

}  // namespace

CompactForest CompactForest::Build(const std::vector<ForestNode>& nodes,
                                   const std::vector<std::int32_t>& roots, int num_features) {
  CompactForest packed;
  if (roots.empty() || num_features <= 0) return packed;
  const int feature_bits =
      std::max(1, static_cast<int>(std::bit_width(static_cast<unsigned>(num_features - 1))));
  if (feature_bits >= 32 || nodes.size() > (std::uint64_t{1} << (32 - feature_bits))) {
    return packed;
  }
  packed.feature_bits_ = feature_bits;
  packed.num_features_ = num_features;
  packed.nodes_.resize(nodes.size());
  packed.leaf_values_.assign(nodes.size(), 0.f);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const ForestNode& node = nodes[i];
    PackedNode& out = packed.nodes_[i];
    if (node.feature < 0) {
      // Self-loop: x > +inf is false for every x (NaN included), so the walk stays here.
      out.threshold = std::numeric_limits<float>::infinity();
      out.word = static_cast<std::uint32_t>(i) << feature_bits;
      packed.leaf_values_[i] = node.value;
    } else {
      out.threshold = node.value;
      out.word = (static_cast<std::uint32_t>(node.left) << feature_bits) |
                 static_cast<std::uint32_t>(node.feature);
    }
  }
  packed.roots_.assign(roots.begin(), roots.end());
  return packed;
}

void CompactForest::AccumulateLeafValues(const float* const* rows, int count, double* sums,
                                         int tree_begin, int tree_end) const {
  // The proposal regressors have 20 features (5 bits), the pixel edge forest 49 (6 bits).
  switch (feature_bits_) {
    case 1:
      return AccumulateCopied<1>(rows, count, sums, tree_begin, tree_end);
    case 2:
      return AccumulateCopied<2>(rows, count, sums, tree_begin, tree_end);
    case 3:
      return AccumulateCopied<3>(rows, count, sums, tree_begin, tree_end);
    case 4:
      return AccumulateCopied<4>(rows, count, sums, tree_begin, tree_end);
    case 5:
      return AccumulateCopied<5>(rows, count, sums, tree_begin, tree_end);
    case 6:
      return AccumulateCopied<6>(rows, count, sums, tree_begin, tree_end);
    case 7:
      return AccumulateCopied<7>(rows, count, sums, tree_begin, tree_end);
    default:  // wider rows: the same walk with the width read at run time
      return AccumulateCopied<0>(rows, count, sums, tree_begin, tree_end);
  }
}

template <int kFeatureBits>
void CompactForest::AccumulateCopied(const float* const* rows, int count, double* sums,
                                     int tree_begin, int tree_end) const {
  tree_begin = std::max(tree_begin, 0);
  tree_end = std::min(tree_end, static_cast<int>(roots_.size()));
  if (count <= 0 || tree_begin >= tree_end) return;
  const int bits = kFeatureBits > 0 ? kFeatureBits : feature_bits_;
  const std::size_t stride = std::size_t{1} << bits;
  const std::uint32_t mask = (std::uint32_t{1} << bits) - 1;
  // Whole lane groups: the spare lanes of a partial last group walk rows of zeros (harmless:
  // their leaves are never added).
  const int padded_rows = (count + kLanes - 1) / kLanes * kLanes;
  // Only the features are written: the stride's spare slots are never read (features <
  // num_features_), and zeroing them would double the memory traffic of the copy.
  const auto copied = std::make_unique_for_overwrite<float[]>(padded_rows * stride);
  for (int r = 0; r < count; ++r) std::copy_n(rows[r], num_features_, &copied[r * stride]);
  std::fill(copied.get() + count * stride, copied.get() + padded_rows * stride, 0.f);
  const PackedNode* const nodes = nodes_.data();
  for (int tree = tree_begin; tree < tree_end; ++tree) {
    const std::uint32_t root = roots_[tree];
    for (int first = 0; first < count; first += kLanes) {
      const float* const group = &copied[first * stride];
      std::array<std::uint32_t, kLanes> at;
      at.fill(root);
      // A split always moves to a later node and a leaf never moves, so extra steps are
      // harmless and the walk is over when a step moves no lane. That test costs as much as
      // the step itself, so it is made only on every kStepsPerCheck-th step.
      const auto step = [&](bool check) {
        bool moved = false;
        for (int k = 0; k < kLanes; ++k) {
          const PackedNode node = nodes[at[k]];
          const float x = group[k * stride + (node.word & mask)];
          const std::uint32_t next = (node.word >> bits) + (x > node.threshold ? 1u : 0u);
          if (check) moved |= next != at[k];
          at[k] = next;
        }
        return moved;
      };
      do {
        for (int s = 1; s < kStepsPerCheck; ++s) step(false);
      } while (step(true));
      const int used = std::min(kLanes, count - first);
      for (int k = 0; k < used; ++k) sums[first + k] += leaf_values_[at[k]];
    }
  }
}

}  // namespace tod
