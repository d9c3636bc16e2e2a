#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <string_view>

#include "core/base/checksum.h"
#include "core/forest/random_forest.h"
#include "tests/forest/fitted_forest.h"

namespace tod {
namespace {

RandomForest SmallForest() {
  std::mt19937 gen(21);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  cv::Mat1f x(120, 3);
  std::vector<float> y(120);
  for (int r = 0; r < x.rows; ++r) {
    for (int c = 0; c < 3; ++c) x(r, c) = uniform(gen);
    y[r] = x(r, 0) * x(r, 1) + x(r, 2);
  }
  ForestParams p;
  p.num_trees = 4;
  p.max_features = 2;
  p.min_leaf_size = 8;
  p.threads = 1;
  return FittedForest(x, y, p);
}

std::string Serialise(const RandomForest& forest) {
  Result<std::string> bytes = EncodeModel(forest);
  EXPECT_TRUE(bytes.ok());
  return bytes.ok() ? std::move(bytes).value() : std::string();
}

Result<RandomForest> Parse(const std::string& bytes) {
  return DecodeModel<RandomForest>(bytes, "model.bin");
}

// FNV-1a, as the format specifies, to forge streams whose checksum is right but content wrong.
void Reseal(std::string& bytes) {
  const std::uint64_t hash = Fnv1a64(std::string_view(bytes).substr(0, bytes.size() - 8));
  for (int i = 0; i < 8; ++i) bytes[bytes.size() - 8 + i] = static_cast<char>(hash >> (8 * i));
}

void PutI32(std::string& bytes, std::size_t offset, std::int32_t v) {
  for (int i = 0; i < 4; ++i)
    bytes[offset + i] = static_cast<char>(static_cast<std::uint32_t>(v) >> (8 * i));
}

constexpr std::size_t kHeaderBytes = 28;

TEST(RandomForestIo, RoundTripGivesIdenticalPredictions) {
  const RandomForest forest = SmallForest();
  const std::string bytes = Serialise(forest);
  // magic + version + counts + roots + 12 bytes per node + checksum
  EXPECT_EQ(bytes.size(), kHeaderBytes + 4u * forest.num_trees() + 12u * forest.num_nodes() + 8u);
  EXPECT_EQ(bytes.substr(0, 7), "TODFRST");
  const Result<RandomForest> loaded = Parse(bytes);
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->num_trees(), forest.num_trees());
  EXPECT_EQ(loaded->num_features(), 3);
  EXPECT_EQ(loaded->num_nodes(), forest.num_nodes());
  for (float a = 0.f; a <= 1.f; a += 0.125f) {
    for (float b = 0.f; b <= 1.f; b += 0.25f) {
      const float row[3] = {a, b, 1.f - a};
      EXPECT_EQ(loaded->Predict(row), forest.Predict(row));
    }
  }
  EXPECT_EQ(Serialise(*loaded), bytes);
}

TEST(RandomForestIo, EmptyForestRoundTrips) {
  const Result<RandomForest> loaded = Parse(Serialise(RandomForest()));
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_TRUE(loaded->empty());
}

TEST(RandomForestIo, EveryTruncationIsAnError) {
  const std::string bytes = Serialise(SmallForest());
  for (std::size_t length = 0; length < bytes.size(); ++length) {
    const Result<RandomForest> loaded = Parse(bytes.substr(0, length));
    ASSERT_FALSE(loaded.ok()) << "length " << length;
    EXPECT_EQ(loaded.status().code(), StatusCode::kDataLoss);
    EXPECT_NE(loaded.status().message().find("model.bin"), std::string::npos);
    if (length >= 8) {
      EXPECT_NE(loaded.status().message().find("truncated"), std::string::npos);
    }
  }
}

TEST(RandomForestIo, GarbageAndFlippedBytesAreErrors) {
  const Result<RandomForest> garbage = Parse(std::string(200, '\x5A'));
  ASSERT_FALSE(garbage.ok());
  EXPECT_NE(garbage.status().message().find("bad magic"), std::string::npos);

  const std::string bytes = Serialise(SmallForest());
  for (std::size_t i = 0; i < bytes.size(); i += 7) {
    std::string corrupted = bytes;
    corrupted[i] = static_cast<char>(corrupted[i] ^ 0x10);
    EXPECT_FALSE(Parse(corrupted).ok()) << "byte " << i;
  }
}

TEST(RandomForestIo, HugeCountsAreRejectedWithoutAllocating) {
  std::string bytes = Serialise(SmallForest());
  std::string huge_nodes = bytes;
  for (int i = 0; i < 8; ++i) huge_nodes[20 + i] = '\xFF';
  Result<RandomForest> loaded = Parse(huge_nodes);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("nodes (limit"), std::string::npos);

  // Plausible count (2^27 nodes = 1.5 GiB) but the stream is short: truncated, quickly.
  std::string short_stream = bytes;
  PutI32(short_stream, 20, 1 << 27);
  PutI32(short_stream, 24, 0);
  loaded = Parse(short_stream);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("truncated"), std::string::npos);
}

TEST(RandomForestIo, StructuralErrorsAreNamedEvenWithValidChecksum) {
  const RandomForest forest = SmallForest();
  const std::string bytes = Serialise(forest);
  const std::size_t nodes_at = kHeaderBytes + 4u * forest.num_trees();

  std::string bad_feature = bytes;  // the first root is a split node (forest is not trivial)
  PutI32(bad_feature, nodes_at, 3);
  Reseal(bad_feature);
  Result<RandomForest> loaded = Parse(bad_feature);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("node 0 has feature index 3"), std::string::npos)
      << loaded.status().message();

  std::string cycle = bytes;  // child pointing back at its parent
  PutI32(cycle, nodes_at + 8, 0);
  Reseal(cycle);
  loaded = Parse(cycle);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("child index 0"), std::string::npos);

  std::string bad_root = bytes;
  PutI32(bad_root, kHeaderBytes, static_cast<std::int32_t>(forest.num_nodes()));
  Reseal(bad_root);
  loaded = Parse(bad_root);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("root index"), std::string::npos);

  std::string bad_version = bytes;
  PutI32(bad_version, 8, 7);
  Reseal(bad_version);
  loaded = Parse(bad_version);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kFailedPrecondition);

  std::string resealed = bytes;
  Reseal(resealed);
  EXPECT_EQ(resealed, bytes);  // the forging helper matches the format
}

}  // namespace
}  // namespace tod
