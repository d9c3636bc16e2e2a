// PredictBatch (both overloads) against hand-built forests whose answers are worked out by hand,
// and against Predict on trained forests: the packed batch path must give the same floats.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/forest/random_forest.h"
#include "tests/forest/fitted_forest.h"

namespace tod {
namespace {

struct HandNode {
  std::int32_t feature;  // -1 = leaf
  float value;           // threshold or leaf value
  std::int32_t left;     // -1 for a leaf
};

// Writes the documented binary format (random_forest_io.cc) for the given nodes and loads it.
RandomForest LoadHandBuilt(int num_features, const std::vector<std::int32_t>& roots,
                           const std::vector<HandNode>& nodes) {
  std::string bytes("TODFRST", 8);
  const auto put = [&bytes](std::uint64_t v, int size) {
    for (int i = 0; i < size; ++i) bytes.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  put(1, 4);  // version
  put(static_cast<std::uint64_t>(num_features), 4);
  put(roots.size(), 4);
  put(nodes.size(), 8);
  for (const std::int32_t root : roots) put(static_cast<std::uint32_t>(root), 4);
  for (const HandNode& node : nodes) {
    std::uint32_t bits;
    std::memcpy(&bits, &node.value, sizeof bits);
    put(static_cast<std::uint32_t>(node.feature), 4);
    put(bits, 4);
    put(static_cast<std::uint32_t>(node.left), 4);
  }
  std::uint64_t hash = 0xCBF29CE484222325ULL;
  for (const char c : bytes) hash = (hash ^ static_cast<unsigned char>(c)) * 0x100000001B3ULL;
  put(hash, 8);
  Result<RandomForest> loaded = DecodeModel<RandomForest>(bytes, "hand-built");
  EXPECT_TRUE(loaded.ok()) << loaded.status().message();
  return loaded.ok() ? std::move(loaded).value() : RandomForest();
}

// Tree A (root 0): x0 <= 0.5 -> leaf 1; else x1 <= 0.25 -> leaf 2, else leaf 4.
// Tree B (root 5): a single leaf 10. Tree C reuses tree A's root (shared nodes are legal).
// So the forest predicts (a + 10 + a) / 3 with a in {1, 2, 4}.
RandomForest ThreeTreeForest() {
  return LoadHandBuilt(
      2, {0, 5, 0},
      {{0, 0.5f, 1}, {-1, 1.f, -1}, {1, 0.25f, 3}, {-1, 2.f, -1}, {-1, 4.f, -1}, {-1, 10.f, -1}});
}

float Mean3(double a) { return static_cast<float>((a + 10.0 + a) / 3.0); }

TEST(BatchPrediction, HandBuiltForestGivesHandComputedValues) {
  const RandomForest forest = ThreeTreeForest();
  ASSERT_EQ(forest.num_trees(), 3);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  // Thresholds are inclusive on the left; NaN compares false, so it goes left everywhere.
  const std::vector<std::pair<std::array<float, 2>, double>> cases = {
      {{0.2f, 0.9f}, 1.0}, {{0.5f, 0.9f}, 1.0}, {{0.7f, 0.1f}, 2.0},  {{0.7f, 0.25f}, 2.0},
      {{0.7f, 0.9f}, 4.0}, {{nan, 0.9f}, 1.0},  {{0.7f, nan}, 2.0},   {{0.7f, inf}, 4.0},
      {{inf, -inf}, 2.0},  {{-inf, inf}, 1.0},  {{0.51f, 0.26f}, 4.0}};
  // 3 copies of the cases: 33 rows, so several lock-step groups and a partial last one.
  cv::Mat1f rows(3 * static_cast<int>(cases.size()), 2);
  std::vector<float> expected;
  for (int copy = 0; copy < 3; ++copy) {
    for (std::size_t c = 0; c < cases.size(); ++c) {
      const int r = copy * static_cast<int>(cases.size()) + static_cast<int>(c);
      rows(r, 0) = cases[c].first[0];
      rows(r, 1) = cases[c].first[1];
      expected.push_back(Mean3(cases[c].second));
    }
  }
  EXPECT_EQ(forest.PredictBatch(rows), expected);
  for (int r = 0; r < rows.rows; ++r) EXPECT_EQ(forest.Predict(rows[r]), expected[r]) << r;

  const std::vector<int> subset = {32, 0, 4, 4, 2};
  const std::vector<float> some = forest.PredictBatch(rows, subset);
  EXPECT_EQ(some, (std::vector<float>{Mean3(4.0), Mean3(1.0), Mean3(4.0), Mean3(4.0), Mean3(2.0)}));
}

// One tree shaped like a caterpillar: split j (node 0, then 2j - 1) tests x[j % features] > 0.5
// and goes right to a leaf holding j, left to the next split; the last split's left leaf holds
// -1. Its depth is splits + 1, which exercises long lock-step walks.
RandomForest Caterpillar(int num_features, int splits) {
  std::vector<HandNode> nodes(2 * splits + 1);
  for (int j = 0; j < splits; ++j) {
    const int at = j == 0 ? 0 : 2 * j - 1;
    nodes[at] = {j % num_features, 0.5f, 2 * j + 1};
    nodes[2 * j + 2] = {-1, static_cast<float>(j), -1};
  }
  nodes[2 * splits - 1] = {-1, -1.f, -1};
  return LoadHandBuilt(num_features, {0}, nodes);
}

TEST(BatchPrediction, DeepUnbalancedTreeIsWalkedToTheEnd) {
  const RandomForest forest = Caterpillar(4, 300);  // 601 nodes, depth 301
  ASSERT_EQ(forest.num_nodes(), 601);
  cv::Mat1f rows(10, 4, 0.f);  // all zeros: left all the way to -1
  rows(1, 2) = 1.f;            // first split on feature 2 is split 2
  rows(2, 3) = 1.f;            // split 3
  rows(3, 0) = 0.6f;           // split 0 already goes right
  rows(4, 1) = 0.5f;           // 0.5 is not > 0.5: never right
  rows(5, 1) = 0.75f;          // split 1
  rows(5, 0) = 0.75f;          // ... but split 0 comes first
  const std::vector<float> expected = {-1.f, 2.f, 3.f, 0.f, -1.f, 0.f, -1.f, -1.f, -1.f, -1.f};
  EXPECT_EQ(forest.PredictBatch(rows), expected);
  EXPECT_EQ(forest.PredictBatch(rows, {4, 1}), (std::vector<float>{-1.f, 2.f}));
}

TEST(BatchPrediction, ForestTooLargeToPackStillPredictsCorrectly) {
  // 65 537 features need 17 bits, leaving 15 for node indices (32 768 nodes): this tree of
  // 32 771 nodes cannot be packed, so PredictBatch walks the stored nodes instead.
  constexpr int kFeatures = 65537;
  const RandomForest forest = Caterpillar(kFeatures, 16385);
  ASSERT_EQ(forest.num_nodes(), 32771);
  cv::Mat1f rows(4, kFeatures, 0.f);
  rows(1, 7) = 1.f;
  rows(2, 100) = 1.f;
  rows(2, 5) = 1.f;
  rows(3, 16384) = 1.f;  // the last split
  const std::vector<float> expected = {-1.f, 7.f, 5.f, 16384.f};
  EXPECT_EQ(forest.PredictBatch(rows), expected);
  EXPECT_EQ(forest.PredictBatch(rows, {3, 3, 0}), (std::vector<float>{16384.f, 16384.f, -1.f}));
  for (int r = 0; r < rows.rows; ++r) EXPECT_EQ(forest.Predict(rows[r]), expected[r]);
}

struct Data {
  cv::Mat1f x;
  std::vector<float> y;
};

Data MakeData(int rows, int cols, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> uniform(0.f, 1.f);
  Data d{cv::Mat1f(rows, cols), std::vector<float>(rows)};
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) d.x(r, c) = uniform(gen);
    d.y[r] = std::sin(5.f * d.x(r, 0)) + d.x(r, 1) * d.x(r, 2);
  }
  return d;
}

RandomForest DeepForest() {
  const Data train = MakeData(400, 3, 31);
  ForestParams p;
  p.num_trees = 12;
  p.max_features = 2;
  p.min_leaf_size = 1;  // deep, unbalanced trees
  p.threads = 1;
  return FittedForest(train.x, train.y, p);
}

TEST(BatchPrediction, ManyBlocksMatchPredictBitForBit) {
  const RandomForest forest = DeepForest();
  ASSERT_EQ(forest.num_trees(), 12);
  // Over two blocks' worth of rows, and a partial lock-step group at the end.
  const int block = forest.PredictionBlockRows();
  ASSERT_GE(block, 1024);
  ASSERT_LE(block, 20000) << "this small forest should get small blocks";
  const int rows = 2 * block + 1003;
  const Data test = MakeData(rows, 3, 32);
  const std::vector<float> batch = forest.PredictBatch(test.x);
  ASSERT_EQ(batch.size(), static_cast<std::size_t>(rows));
  int mismatches = 0;
  for (int r = 0; r < test.x.rows; ++r) mismatches += batch[r] != forest.Predict(test.x[r]);
  EXPECT_EQ(mismatches, 0);

  std::vector<int> subset;  // backwards, every third row, each twice
  for (int r = test.x.rows - 1; r >= 0; r -= 3) subset.insert(subset.end(), {r, r});
  const std::vector<float> some = forest.PredictBatch(test.x, subset);
  ASSERT_EQ(some.size(), subset.size());
  for (std::size_t k = 0; k < subset.size(); ++k) EXPECT_EQ(some[k], batch[subset[k]]) << k;
}

// The screened walk in one piece, on one thread, without a deadline.
std::vector<float> Screened(const RandomForest& forest, const cv::Mat1f& rows, int trees,
                            float final_at_most) {
  ForestWalkOptions walk;
  walk.screening = ForestScreening{.trees = trees, .final_at_most = final_at_most};
  return forest.PredictBatchScreened(rows, walk).values;
}

// The walk in pieces of trees (what a frame budget stops between): consecutive ranges add up to
// PredictBatch's sums bit for bit; ranges are clamped to the forest; a wrong width adds nothing.
TEST(BatchPrediction, TreeRangesAddUpToPredictBatchBitForBit) {
  const RandomForest forest = DeepForest();
  const Data test = MakeData(3000, 3, 34);
  std::vector<double> sums(3000, 0.0);
  forest.AccumulateTreeRange(test.x, -4, 5, sums.data());
  forest.AccumulateTreeRange(test.x, 5, 5, sums.data());  // empty
  forest.AccumulateTreeRange(test.x, 5, 99, sums.data());
  const std::vector<float> batch = forest.PredictBatch(test.x);
  int mismatches = 0;
  for (int r = 0; r < test.x.rows; ++r)
    mismatches += static_cast<float>(sums[r] / forest.num_trees()) != batch[r];
  EXPECT_EQ(mismatches, 0);
  // The first trees alone: their mean, as the screened walk stops at it.
  std::vector<double> first(3000, 0.0);
  forest.AccumulateTreeRange(test.x, 0, 4, first.data());
  const std::vector<float> screened = Screened(forest, test.x, 4, 1e9f);
  for (int r = 0; r < test.x.rows; ++r)
    ASSERT_EQ(static_cast<float>(first[r] / 4.0), screened[r]) << r;
  std::vector<double> untouched(3000, 0.0);
  forest.AccumulateTreeRange(MakeData(3000, 4, 35).x, 0, 12, untouched.data());
  EXPECT_EQ(untouched, std::vector<double>(3000, 0.0));
}

TEST(BatchPrediction, RowsMayBeAViewIntoAWiderMatrix) {
  const RandomForest forest = DeepForest();
  const Data wide = MakeData(50, 7, 33);
  const cv::Mat1f view = wide.x.colRange(2, 5);  // not continuous: row stride is 7 floats
  ASSERT_FALSE(view.isContinuous());
  const std::vector<float> batch = forest.PredictBatch(view);
  ASSERT_EQ(batch.size(), 50u);
  for (int r = 0; r < view.rows; ++r) EXPECT_EQ(batch[r], forest.Predict(view[r])) << r;
  EXPECT_EQ(forest.PredictBatch(view, {49, 0}), (std::vector<float>{batch[49], batch[0]}));
}

TEST(BatchPrediction, LoadedForestPredictsTheSameBatch) {
  const RandomForest forest = DeepForest();
  const Result<std::string> bytes = EncodeModel(forest);
  ASSERT_TRUE(bytes.ok());
  Result<RandomForest> loaded = DecodeModel<RandomForest>(*bytes, "round trip");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const Data test = MakeData(300, 3, 34);
  EXPECT_EQ(loaded.value().PredictBatch(test.x), forest.PredictBatch(test.x));
  // A copy carries its packed form along.
  const RandomForest copy = loaded.value();
  EXPECT_EQ(copy.PredictBatch(test.x), forest.PredictBatch(test.x));
}

// The batch walk copies rows to a stride fixed per feature-count class (1, 2, 3-4, ... 65-128
// features) and walks wider rows through pointers: each width must give Predict's floats, with
// the highest feature indices in use (the target depends on the first and the last column).
TEST(BatchPrediction, EveryFeatureWidthMatchesPredict) {
  for (const int cols : {1, 2, 3, 5, 20, 49, 64, 65, 128, 129, 200}) {
    std::mt19937 gen(40 + static_cast<unsigned>(cols));
    std::uniform_real_distribution<float> uniform(0.f, 1.f);
    const auto make = [&](int rows) {
      Data d{cv::Mat1f(rows, cols), std::vector<float>(rows)};
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) d.x(r, c) = uniform(gen);
        d.y[r] = std::sin(5.f * d.x(r, 0)) + 2.f * d.x(r, cols - 1);
      }
      return d;
    };
    const Data train = make(300);
    ForestParams p;
    p.num_trees = 4;
    p.max_features = cols;
    p.min_leaf_size = 1;
    p.threads = 1;
    const RandomForest forest = FittedForest(train.x, train.y, p);
    ASSERT_EQ(forest.num_trees(), 4) << cols;
    const Data test = make(77);  // not a multiple of the lane count
    const std::vector<float> batch = forest.PredictBatch(test.x);
    ASSERT_EQ(batch.size(), 77u) << cols;
    int mismatches = 0;
    for (int r = 0; r < test.x.rows; ++r) mismatches += batch[r] != forest.Predict(test.x[r]);
    EXPECT_EQ(mismatches, 0) << cols << " features";
  }
}

TEST(BatchPrediction, SubsetRejectsBadInput) {
  const RandomForest forest = ThreeTreeForest();
  const cv::Mat1f rows(4, 2, 0.f);
  EXPECT_TRUE(forest.PredictBatch(rows, {}).empty());
  EXPECT_TRUE(forest.PredictBatch(rows, {0, 4}).empty());               // past the last row
  EXPECT_TRUE(forest.PredictBatch(rows, {-1}).empty());                 // negative
  EXPECT_TRUE(forest.PredictBatch(cv::Mat1f(4, 3, 0.f), {0}).empty());  // wrong column count
  EXPECT_EQ(forest.PredictBatch(rows, {3}), (std::vector<float>{Mean3(1.0)}));

  const RandomForest untrained;  // predicts 0, as Predict does, but indices are still checked
  EXPECT_EQ(untrained.PredictBatch(rows, {1, 1, 2}), (std::vector<float>{0.f, 0.f, 0.f}));
  EXPECT_TRUE(untrained.PredictBatch(rows, {4}).empty());
}

// The early exit: with the hand-built forest (a, 10, a), screening on the first tree stops the
// rows whose a is at most the bound at a; the others get the whole mean, exactly PredictBatch's.
TEST(ScreenedPrediction, HandBuiltForestStopsOnlyTheRowsAtOrUnderTheBound) {
  const RandomForest forest = ThreeTreeForest();
  // Rows reaching a = 1, 2 and 4 in tree A.
  cv::Mat1f rows(3, 2);
  rows(0, 0) = 0.2f, rows(0, 1) = 0.f;   // x0 <= 0.5: a = 1
  rows(1, 0) = 0.9f, rows(1, 1) = 0.1f;  // a = 2
  rows(2, 0) = 0.9f, rows(2, 1) = 0.9f;  // a = 4
  const std::vector<float> full = forest.PredictBatch(rows);
  const std::vector<float> screened = Screened(forest, rows, 1, 2.f);
  ASSERT_EQ(screened.size(), 3u);
  EXPECT_EQ(screened[0], 1.f);  // the first tree's value: at or under the bound
  EXPECT_EQ(screened[1], 2.f);
  EXPECT_EQ(screened[2], full[2]);  // over it: the whole forest, bit for bit
  EXPECT_EQ(full[2], Mean3(4.0));
}

// A forest of 12 trees fitted to 3000 rows of 6 features (the screening tests' forest).
RandomForest TwelveTreeForest() {
  const Data train = MakeData(3000, 6, 5);
  ForestParams p;
  p.num_trees = 12;
  p.min_leaf_size = 3;
  p.threads = 1;
  return FittedForest(train.x, train.y, p);
}

// Screening off (no trees, or every tree) is PredictBatch itself, and on a trained forest every
// row that goes on is bit-identical to PredictBatch while the stopped ones hold the first
// trees' mean, at or under the bound: over many blocks of rows.
TEST(ScreenedPrediction, TrainedForestGoesOnBitForBitAndStopsAtTheFirstTreesMean) {
  const RandomForest forest = TwelveTreeForest();
  ASSERT_EQ(forest.num_trees(), 12);
  const Data test = MakeData(20000, 6, 6);
  const std::vector<float> full = forest.PredictBatch(test.x);
  EXPECT_EQ(Screened(forest, test.x, 0, 0.5f), full);
  EXPECT_EQ(Screened(forest, test.x, 12, 0.5f), full);
  const float bound = 0.4f;
  const std::vector<float> screened = Screened(forest, test.x, 4, bound);
  ASSERT_EQ(screened.size(), full.size());
  int stopped = 0, went_on = 0;
  for (int r = 0; r < test.x.rows; ++r) {
    if (screened[r] == full[r]) {
      ++went_on;
      continue;
    }
    ++stopped;
    EXPECT_LE(screened[r], bound) << r;
  }
  // Both kinds occur, so both paths are exercised.
  EXPECT_GT(stopped, 1000);
  EXPECT_GT(went_on, 1000);
}

// Pieces of trees and threads change nothing; a deadline already past stops the walk after its
// first piece (the screening trees when screening), and the rows still going on get the mean of
// the trees walked; no rows: no tree is left out.
TEST(ScreenedPrediction, PiecesThreadsAndADeadlineWalkTheSameSums) {
  const RandomForest forest = TwelveTreeForest();
  const Data test = MakeData(9000, 6, 7);
  const std::vector<float> one_piece = Screened(forest, test.x, 4, 0.4f);
  ForestWalkOptions walk;
  walk.screening = ForestScreening{.trees = 4, .final_at_most = 0.4f};
  walk.trees_per_piece = 3;
  walk.threads = 2;
  const ForestWalk pieces = forest.PredictBatchScreened(test.x, walk);
  EXPECT_EQ(pieces.trees, 12);
  EXPECT_EQ(pieces.values, one_piece);

  walk.deadline = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  const ForestWalk stopped = forest.PredictBatchScreened(test.x, walk);
  EXPECT_EQ(stopped.trees, 4);
  std::vector<double> first(9000, 0.0);
  forest.AccumulateTreeRange(test.x, 0, 4, first.data());
  int mismatches = 0;
  for (int r = 0; r < test.x.rows; ++r)
    mismatches += static_cast<float>(first[r] / 4.0) != stopped.values[r];
  EXPECT_EQ(mismatches, 0);

  walk.screening = ForestScreening{};  // no screening: the first piece is trees_per_piece
  const ForestWalk unscreened = forest.PredictBatchScreened(test.x, walk);
  EXPECT_EQ(unscreened.trees, 3);
  EXPECT_EQ(forest.PredictBatchScreened(cv::Mat1f(0, 6), walk).trees, 12);
  EXPECT_TRUE(forest.PredictBatchScreened(MakeData(10, 4, 8).x, walk).values.empty());
}

}  // namespace
}  // namespace tod
