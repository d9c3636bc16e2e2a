// Random-forest regression (ALGORITHM.md §6.3): bootstrap samples, mtry features tried per split,
// minimum leaf size, squared-error reduction, leaf = mean target, prediction = mean over trees.
// Also used as a probabilistic classifier by regressing 0/1 targets.
// Stored in a compact little-endian binary form that loads in milliseconds.
#pragma once

#include <chrono>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/base/binary_io.h"
#include "core/base/status.h"
#include "core/forest/compact_forest.h"
#include "core/forest/forest_node.h"

namespace tod {

struct ForestParams {
  int num_trees = 200;
  int max_features = 6;          // mtry; <= 0 means floor(num_features / 3), at least 1
  int min_leaf_size = 5;         // every leaf holds at least this many bootstrap samples
  int max_depth = 0;             // 0 = unlimited; the root has depth 0
  double sample_fraction = 1.0;  // bootstrap size as a fraction of the training set
  std::uint64_t seed = 1;
  int threads = 0;  // 0 = hardware concurrency
};

// Early exit over a forest's trees in their stored order (a cascade, PredictBatchScreened): every
// row is first walked through the first `trees` trees; a row whose mean over them is at most
// `final_at_most` keeps that mean, every other row goes on through the rest, exactly as without
// screening. trees <= 0 or >= the forest's: every tree on every row (the reference). The trees
// of a forest are drawn alike, so the first ones' mean estimates the whole forest's; a caller
// picks `final_at_most` where the difference no longer matters.
struct ForestScreening {
  int trees = 0;
  float final_at_most = 0.f;
};

// How RandomForest::PredictBatchScreened walks a batch.
struct ForestWalkOptions {
  ForestScreening screening;
  // After the screening trees (or from the first tree without screening) the trees are walked
  // this many at a time (0: all that are left at once), and no piece starts once `deadline` has
  // passed: the rows still going on then get the mean of the trees walked so far. A caller that
  // must bound its time (a frame budget) sets both.
  int trees_per_piece = 0;
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  // The rows of a piece are split over up to this many of OpenCV's threads (each share at least
  // kMinRowsPerThread rows); every row's sum is the same whichever thread walks it.
  int threads = 1;
  static constexpr int kMinRowsPerThread = 2048;
};

struct ForestWalk {
  std::vector<float> values;  // one per row
  int trees = 0;              // trees walked for the rows that went on past the screening
};

class RandomForest {
 public:
  RandomForest() = default;
  // features: one row per sample (CV_32F); targets: one per row. Invalid input (shape
  // mismatch, no rows, non-finite values, bad params) is an error naming the offending field.
  static Result<RandomForest> Fit(const cv::Mat1f& features, const std::vector<float>& targets,
                                  const ForestParams& params);

  // One forest holding the trees of `parts` in order (e.g. forests fitted on different bags of
  // samples). Its prediction is the mean over all their trees, which for parts with equally
  // many trees is the mean of the parts' predictions. The parts must agree on num_features().
  static Result<RandomForest> Join(const std::vector<RandomForest>& parts);

  // row must hold num_features() values. An empty forest predicts 0.
  float Predict(const float* row) const;
  // One prediction per row; empty when features.cols != num_features() (for a non-empty forest).
  // Bit-identical to calling Predict on every row, and much faster for many rows (see
  // compact_forest.h). Single-threaded; safe to call concurrently.
  std::vector<float> PredictBatch(const cv::Mat1f& features) const;
  // One prediction per entry of `subset` (row indices into features, any order, repeats
  // allowed), equal to Predict(features[subset[k]]); the other rows are not read. Empty when
  // features.cols != num_features() (for a non-empty forest) or an index is outside
  // [0, features.rows).
  std::vector<float> PredictBatch(const cv::Mat1f& features, const std::vector<int>& subset) const;

  // The batch walk in pieces of trees, with the early exit and a deadline (the one walk behind
  // the pixel edge classifier's and the occlusion classifier's, ForestWalkOptions). Without
  // screening, pieces or deadline its values are PredictBatch's, bit for bit. Empty values when
  // features.cols != num_features() (for a non-empty forest).
  ForestWalk PredictBatchScreened(const cv::Mat1f& features,
                                  const ForestWalkOptions& options) const;

  // The walk in pieces of trees: adds, for every row of `features`, the outputs of trees
  // [tree_begin, tree_end) (clamped to the forest) to sums[row], in tree order. Calls over
  // consecutive ranges from 0 to num_trees() leave in sums what PredictBatch divides by
  // num_trees(), bit for bit. Does nothing when features.cols != num_features().
  void AccumulateTreeRange(const cv::Mat1f& features, int tree_begin, int tree_end,
                           double* sums) const;

  int num_features() const { return num_features_; }
  int num_trees() const { return static_cast<int>(tree_roots_.size()); }
  bool empty() const { return tree_roots_.empty(); }
  // Total node count over all trees (split nodes + leaves).
  std::int64_t num_nodes() const { return static_cast<std::int64_t>(nodes_.size()); }
  // How many rows PredictBatch walks through one tree before going on to the next (depends on
  // the trees' size; for diagnostics and tests).
  int PredictionBlockRows() const;
  // Number of leaves of one tree (for tests and diagnostics); 0 for an index out of range.
  int CountLeaves(int tree) const;

  // The file format is in random_forest_io.cc. Save never fails (a Status for the model
  // convention of binary_io.h); Load's errors name the reader's source (e.g. the file path).
  Status Save(BinaryWriter& out) const;
  static Result<RandomForest> Load(BinaryReader& in);

 private:
  // See forest_node.h: 12 bytes, children adjacent (right = left + 1) and after their parent.
  using Node = ForestNode;
  friend class ForestTreeBuilder;

  // Sums the trees' outputs for `count` rows (tree order per row, as Predict) and writes the
  // means to out[0, count).
  void PredictRows(const float* const* rows, int count, float* out) const;
  // Adds the outputs of trees [tree_begin, tree_end) to sums[0, count), tree order per row, in
  // blocks of rows (PredictionBlockRows).
  void AccumulateTrees(const float* const* rows, int count, int tree_begin, int tree_end,
                       double* sums) const;
  // AccumulateTrees for `rows`, split over up to `threads` threads (ForestWalkOptions::threads).
  void AccumulateOnThreads(const std::vector<const float*>& rows, int tree_begin, int tree_end,
                           std::vector<double>& sums, int threads) const;
  // Rebuilds compact_ from nodes_ and tree_roots_; called whenever those change.
  void PackForPrediction();

  int num_features_ = 0;
  std::vector<Node> nodes_;               // all trees, one after another
  std::vector<std::int32_t> tree_roots_;  // index of each tree's root in nodes_
  // The same trees packed for PredictBatch; empty (and nodes_ is walked instead) only when a
  // forest has too many nodes to pack.
  CompactForest compact_;
};

}  // namespace tod
