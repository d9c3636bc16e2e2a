// Binary form of RandomForest (all integers little-endian, floats as IEEE-754 bit patterns):
//   8 bytes  magic "TODFRST\0"
//   u32      format version (1)
//   u32      num_features
//   u32      num_trees
//   u64      num_nodes
//   i32      root index, per tree
//   node     (i32 feature, f32 threshold-or-leaf-value, i32 left child), per node
//   u64      FNV-1a hash of every preceding byte (detects corruption that parses)
// Load trusts nothing: counts are checked against limits before use, nodes are read in bounded
// chunks (a truncated stream claiming a huge count fails before allocating for it), and every
// node is checked so that prediction can neither index out of range nor loop.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <istream>
#include <ostream>
#include <string>
#include <vector>

#include "core/forest/random_forest.h"

namespace tod {
namespace {

constexpr std::array<char, 8> kMagic = {'T', 'O', 'D', 'F', 'R', 'S', 'T', '\0'};
constexpr std::uint32_t kVersion = 1;
constexpr std::uint32_t kMaxFeatures = 1u << 20;
constexpr std::uint32_t kMaxTrees = 1u << 20;
constexpr std::uint64_t kMaxNodes = 1ull << 28;  // 3 GiB of nodes; far above any real forest
constexpr std::size_t kNodeBytes = 12;
constexpr std::uint64_t kNodesPerChunk = 1u << 16;

class Fnv1a {
 public:
  void Update(const unsigned char* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) hash_ = (hash_ ^ data[i]) * 0x100000001B3ULL;
  }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xCBF29CE484222325ULL;
};

std::uint32_t FloatBits(float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

float BitsToFloat(std::uint32_t bits) {
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

class ByteWriter {
 public:
  void Raw(const char* data, std::size_t size) { bytes_.insert(bytes_.end(), data, data + size); }
  void U32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  void U64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  void I32(std::int32_t v) { U32(static_cast<std::uint32_t>(v)); }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// Reads little-endian values, hashing every byte; after a short read ok() is false for good.
class ByteReader {
 public:
  explicit ByteReader(std::istream& in) : in_(in) {}
  bool Raw(unsigned char* out, std::size_t size) {
    if (!ok_) return false;
    in_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(size));
    if (static_cast<std::size_t>(in_.gcount()) != size) {
      ok_ = false;
      return false;
    }
    hash_.Update(out, size);
    return true;
  }
  std::uint64_t Unsigned(int bytes) {
    std::array<unsigned char, 8> buffer{};
    if (!Raw(buffer.data(), bytes)) return 0;
    return Decode(buffer.data(), bytes);
  }
  static std::uint64_t Decode(const unsigned char* p, int bytes) {
    std::uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
    return v;
  }
  bool ok() const { return ok_; }
  std::uint64_t hash() const { return hash_.value(); }

 private:
  std::istream& in_;
  Fnv1a hash_;
  bool ok_ = true;
};

}  // namespace

Status RandomForest::Save(std::ostream& out) const {
  ByteWriter w;
  w.Raw(kMagic.data(), kMagic.size());
  w.U32(kVersion);
  w.U32(static_cast<std::uint32_t>(num_features_));
  w.U32(static_cast<std::uint32_t>(tree_roots_.size()));
  w.U64(nodes_.size());
  for (const std::int32_t root : tree_roots_) w.I32(root);
  for (const Node& node : nodes_) {
    w.I32(node.feature);
    w.U32(FloatBits(node.value));
    w.I32(node.feature >= 0 ? node.left : -1);
  }
  Fnv1a hash;
  hash.Update(reinterpret_cast<const unsigned char*>(w.bytes().data()), w.bytes().size());
  ByteWriter trailer;
  trailer.U64(hash.value());
  out.write(w.bytes().data(), static_cast<std::streamsize>(w.bytes().size()));
  out.write(trailer.bytes().data(), static_cast<std::streamsize>(trailer.bytes().size()));
  if (!out) return Status::Internal("RandomForest::Save: writing the forest to the stream failed");
  return Status::Ok();
}

Result<RandomForest> RandomForest::Load(std::istream& in, const std::string& what) {
  const auto corrupt = [&what](const std::string& problem) {
    return Status::DataLoss(what + ": random forest " + problem);
  };
  const auto truncated = [&](const std::string& part) {
    return corrupt("is truncated (stream ended while reading " + part + ")");
  };
  ByteReader r(in);

  std::array<unsigned char, 8> magic{};
  if (!r.Raw(magic.data(), magic.size())) return truncated("the magic number");
  if (std::memcmp(magic.data(), kMagic.data(), kMagic.size()) != 0) {
    return Status::DataLoss(what + ": not a tod random forest (bad magic number)");
  }
  const auto version = static_cast<std::uint32_t>(r.Unsigned(4));
  const auto num_features = static_cast<std::uint32_t>(r.Unsigned(4));
  const auto num_trees = static_cast<std::uint32_t>(r.Unsigned(4));
  const std::uint64_t num_nodes = r.Unsigned(8);
  if (!r.ok()) return truncated("the header");
  if (version != kVersion) {
    return Status::FailedPrecondition(what + ": random forest format version " +
                                      std::to_string(version) + ", this build reads version " +
                                      std::to_string(kVersion));
  }
  if (num_features > kMaxFeatures) {
    return corrupt("header claims " + std::to_string(num_features) + " features (limit " +
                   std::to_string(kMaxFeatures) + ")");
  }
  if (num_trees > kMaxTrees) {
    return corrupt("header claims " + std::to_string(num_trees) + " trees (limit " +
                   std::to_string(kMaxTrees) + ")");
  }
  if (num_nodes > kMaxNodes) {
    return corrupt("header claims " + std::to_string(num_nodes) + " nodes (limit " +
                   std::to_string(kMaxNodes) + ")");
  }
  if (num_nodes < num_trees || (num_trees > 0 && num_features == 0) ||
      (num_trees == 0 && num_nodes != 0)) {
    return corrupt("header is inconsistent: " + std::to_string(num_trees) + " trees, " +
                   std::to_string(num_nodes) + " nodes, " + std::to_string(num_features) +
                   " features");
  }

  RandomForest forest;
  forest.num_features_ = static_cast<int>(num_features);
  forest.tree_roots_.reserve(num_trees);
  for (std::uint32_t t = 0; t < num_trees; ++t) {
    const auto root = static_cast<std::int32_t>(r.Unsigned(4));
    if (!r.ok()) return truncated("the tree roots");
    if (root < 0 || static_cast<std::uint64_t>(root) >= num_nodes) {
      return corrupt("tree " + std::to_string(t) + " has root index " + std::to_string(root) +
                     " outside [0, " + std::to_string(num_nodes) + ")");
    }
    forest.tree_roots_.push_back(root);
  }

  std::vector<unsigned char> chunk;
  for (std::uint64_t first = 0; first < num_nodes; first += kNodesPerChunk) {
    const std::uint64_t count = std::min(kNodesPerChunk, num_nodes - first);
    chunk.resize(count * kNodeBytes);
    if (!r.Raw(chunk.data(), chunk.size())) return truncated("the nodes");
    for (std::uint64_t k = 0; k < count; ++k) {
      const unsigned char* p = chunk.data() + k * kNodeBytes;
      const std::uint64_t index = first + k;
      Node node;
      node.feature = static_cast<std::int32_t>(ByteReader::Decode(p, 4));
      node.value = BitsToFloat(static_cast<std::uint32_t>(ByteReader::Decode(p + 4, 4)));
      node.left = static_cast<std::int32_t>(ByteReader::Decode(p + 8, 4));
      const std::string where = "node " + std::to_string(index);
      if (!std::isfinite(node.value)) return corrupt(where + " has a non-finite value");
      if (node.feature < -1 || node.feature >= static_cast<std::int32_t>(num_features)) {
        return corrupt(where + " has feature index " + std::to_string(node.feature) +
                       " (features: " + std::to_string(num_features) + ")");
      }
      // Children strictly after their parent: no cycles, so every prediction terminates.
      if (node.feature >= 0 && (node.left < 0 || static_cast<std::uint64_t>(node.left) <= index ||
                                static_cast<std::uint64_t>(node.left) + 1 >= num_nodes)) {
        return corrupt(where + " has child index " + std::to_string(node.left) +
                       " (must be after the node and leave room for the right child below " +
                       std::to_string(num_nodes) + ")");
      }
      if (node.feature < 0 && node.left != -1) {
        return corrupt(where + " is a leaf with child index " + std::to_string(node.left));
      }
      forest.nodes_.push_back(node);
    }
  }
  const std::uint64_t expected_hash = r.hash();
  const std::uint64_t stored_hash = r.Unsigned(8);
  if (!r.ok()) return truncated("the checksum");
  if (stored_hash != expected_hash) return corrupt("checksum mismatch (the data is corrupt)");
  forest.PackForPrediction();
  return forest;
}

}  // namespace tod
