#include "core/forest/compact_forest.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>

namespace tod {
namespace {

// Rows descending one tree in lock-step. Enough independent chains to cover the latency of a
// node load from L2, few enough that the lane state stays in registers.
constexpr int kLanes = 8;
// Steps between tests for "all lanes reached a leaf" (2, 4 and 8 measured within a few percent;
// 4 was best).
constexpr int kStepsPerCheck = 4;

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
  packed.feature_mask_ = (std::uint32_t{1} << feature_bits) - 1;
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

void CompactForest::AccumulateLeafValues(const float* const* rows, int count, double* sums) const {
  const PackedNode* const nodes = nodes_.data();
  const int shift = feature_bits_;
  const std::uint32_t mask = feature_mask_;
  for (const std::uint32_t root : roots_) {
    for (int first = 0; first < count; first += kLanes) {
      // A partial last group repeats its last row in the spare lanes and ignores them.
      const int used = std::min(kLanes, count - first);
      std::array<const float*, kLanes> lane_row;
      std::array<std::uint32_t, kLanes> at;
      for (int k = 0; k < kLanes; ++k) {
        lane_row[k] = rows[first + std::min(k, used - 1)];
        at[k] = root;
      }
      // A split always moves to a later node and a leaf never moves, so extra steps are
      // harmless and the walk is over when a step moves no lane. That test costs as much as
      // the step itself, so it is made only on every kStepsPerCheck-th step.
      const auto step = [&](bool check) {
        bool moved = false;
        for (int k = 0; k < kLanes; ++k) {
          const PackedNode node = nodes[at[k]];
          const std::uint32_t next =
              (node.word >> shift) + (lane_row[k][node.word & mask] > node.threshold ? 1u : 0u);
          if (check) moved |= next != at[k];
          at[k] = next;
        }
        return moved;
      };
      do {
        for (int s = 1; s < kStepsPerCheck; ++s) step(false);
      } while (step(true));
      for (int k = 0; k < used; ++k) sums[first + k] += leaf_values_[at[k]];
    }
  }
}

}  // namespace tod
