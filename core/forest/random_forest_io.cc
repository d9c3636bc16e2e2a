// Binary form of RandomForest, in the encoding of core/base/binary_io.h:
//   8 bytes  magic "TODFRST\0"
//   u32      format version (1)
//   u32      num_features
//   u32      num_trees
//   u64      num_nodes
//   i32      root index, per tree
//   node     (i32 feature, f32 threshold-or-leaf-value, i32 left child), per node
//   u64      FNV-1a hash of every preceding byte of the forest (detects corruption that parses)
// Load trusts nothing: counts are checked against limits and against the bytes left before
// anything is allocated for them, and every node is checked so that prediction can neither
// index out of range nor loop.
#include <cmath>
#include <string>
#include <string_view>

#include "core/base/checksum.h"
#include "core/forest/random_forest.h"

namespace tod {
namespace {

constexpr std::string_view kMagic("TODFRST\0", 8);
constexpr std::uint32_t kVersion = 1;
constexpr std::uint32_t kMaxFeatures = 1u << 20;
constexpr std::uint32_t kMaxTrees = 1u << 20;
constexpr std::uint64_t kMaxNodes = 1ull << 28;  // 3 GiB of nodes; far above any real forest
constexpr std::size_t kRootBytes = 4;
constexpr std::size_t kNodeBytes = 12;
constexpr std::size_t kChecksumBytes = 8;

// Why `node` (at `index` of `num_nodes`) cannot be part of a forest over `num_features`, or "".
std::string NodeProblem(const ForestNode& node, std::uint64_t index, std::uint64_t num_nodes,
                        std::uint32_t num_features) {
  const auto where = [index] { return "node " + std::to_string(index); };  // only on failure
  if (!std::isfinite(node.value)) return where() + " has a non-finite value";
  if (node.feature < -1 || node.feature >= static_cast<std::int64_t>(num_features)) {
    return where() + " has feature index " + std::to_string(node.feature) +
           " (features: " + std::to_string(num_features) + ")";
  }
  // Children strictly after their parent: no cycles, so every prediction terminates.
  if (node.feature >= 0 && (node.left < 0 || static_cast<std::uint64_t>(node.left) <= index ||
                            static_cast<std::uint64_t>(node.left) + 1 >= num_nodes)) {
    return where() + " has child index " + std::to_string(node.left) +
           " (must be after the node and leave room for the right child below " +
           std::to_string(num_nodes) + ")";
  }
  if (node.feature < 0 && node.left != -1) {
    return where() + " is a leaf with child index " + std::to_string(node.left);
  }
  return "";
}

// The counts of a forest file, checked against the limits, against each other and against the
// bytes left in `in`, before anything is allocated for them.
struct ForestCounts {
  std::uint32_t features = 0;
  std::uint32_t trees = 0;
  std::uint64_t nodes = 0;
};

Result<ForestCounts> ReadForestCounts(BinaryReader& in) {
  const auto corrupt = [&in](const std::string& problem) {
    return in.Corrupt("random forest " + problem);
  };
  if (Status status = in.Header(kMagic, kVersion, "tod random forest"); !status.ok()) {
    return status;
  }
  ForestCounts counts;
  counts.features = in.U32("the feature count");
  counts.trees = in.U32("the tree count");
  counts.nodes = in.U64("the node count");
  if (!in.ok()) return in.status();
  if (counts.features > kMaxFeatures) {
    return corrupt("header claims " + std::to_string(counts.features) + " features (limit " +
                   std::to_string(kMaxFeatures) + ")");
  }
  if (counts.trees > kMaxTrees) {
    return corrupt("header claims " + std::to_string(counts.trees) + " trees (limit " +
                   std::to_string(kMaxTrees) + ")");
  }
  if (counts.nodes > kMaxNodes) {
    return corrupt("header claims " + std::to_string(counts.nodes) + " nodes (limit " +
                   std::to_string(kMaxNodes) + ")");
  }
  if (counts.nodes < counts.trees || (counts.trees > 0 && counts.features == 0) ||
      (counts.trees == 0 && counts.nodes != 0)) {
    return corrupt("header is inconsistent: " + std::to_string(counts.trees) + " trees, " +
                   std::to_string(counts.nodes) + " nodes, " + std::to_string(counts.features) +
                   " features");
  }
  // Within the limits the sum cannot overflow; a short file fails here, before any allocation.
  const std::uint64_t body_bytes =
      counts.trees * kRootBytes + counts.nodes * kNodeBytes + kChecksumBytes;
  if (!in.Expect(body_bytes, 1, "the tree roots, nodes and checksum")) return in.status();
  return counts;
}

}  // namespace

Status RandomForest::Save(BinaryWriter& out) const {
  const std::size_t start = out.size();
  out.Header(kMagic, kVersion);
  out.U32(static_cast<std::uint32_t>(num_features_));
  out.U32(static_cast<std::uint32_t>(tree_roots_.size()));
  out.U64(nodes_.size());
  for (const std::int32_t root : tree_roots_) out.I32(root);
  for (const Node& node : nodes_) {
    out.I32(node.feature);
    out.F32(node.value);
    out.I32(node.feature >= 0 ? node.left : -1);
  }
  out.U64(Fnv1a64(out.BytesSince(start)));
  return Status::Ok();
}

Result<RandomForest> RandomForest::Load(BinaryReader& in) {
  const auto corrupt = [&in](const std::string& problem) {
    return in.Corrupt("random forest " + problem);
  };
  const std::size_t start = in.position();
  const Result<ForestCounts> counts = ReadForestCounts(in);
  if (!counts.ok()) return counts.status();
  const std::uint32_t num_features = counts->features;
  const std::uint32_t num_trees = counts->trees;
  const std::uint64_t num_nodes = counts->nodes;

  RandomForest forest;
  forest.num_features_ = static_cast<int>(num_features);
  forest.tree_roots_.reserve(num_trees);
  for (std::uint32_t t = 0; t < num_trees; ++t) {
    const std::int32_t root = in.I32("a tree root");
    if (!in.ok()) return in.status();
    if (root < 0 || static_cast<std::uint64_t>(root) >= num_nodes) {
      return corrupt("tree " + std::to_string(t) + " has root index " + std::to_string(root) +
                     " outside [0, " + std::to_string(num_nodes) + ")");
    }
    forest.tree_roots_.push_back(root);
  }
  forest.nodes_.reserve(static_cast<std::size_t>(num_nodes));
  for (std::uint64_t index = 0; index < num_nodes; ++index) {
    Node node;
    node.feature = in.I32("a node's feature");
    node.value = in.F32("a node's value");
    node.left = in.I32("a node's child");
    if (!in.ok()) return in.status();
    if (const std::string problem = NodeProblem(node, index, num_nodes, num_features);
        !problem.empty()) {
      return corrupt(problem);
    }
    forest.nodes_.push_back(node);
  }
  const std::uint64_t expected_hash = Fnv1a64(in.BytesSince(start));
  const std::uint64_t stored_hash = in.U64("the checksum");
  if (!in.ok()) return in.status();
  if (stored_hash != expected_hash) return corrupt("checksum mismatch (the data is corrupt)");
  forest.PackForPrediction();
  return forest;
}

}  // namespace tod
