#include "core/forest/random_forest.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/core/utility.hpp>
#include <string>
#include <thread>
#include <utility>

#include "core/forest/split_mix.h"
#include "core/forest/tree_builder.h"

namespace tod {
namespace {

constexpr int kMaxTrees = 1 << 20;
constexpr long long kMaxRows = 1 << 30;
constexpr long long kMaxNodes = std::numeric_limits<std::int32_t>::max() - 1;
// Rows per block of tree-major prediction (see PredictionBlockRows).
constexpr int kMinBlockRows = 1024;
constexpr double kBlockRowBytesPerTreeByte = 24.0;

Status ValidateTrainingInput(const cv::Mat1f& features, const std::vector<float>& targets,
                             const ForestParams& params) {
  const std::string where = "RandomForest::Fit: ";
  if (features.empty() || features.rows <= 0 || features.cols <= 0) {
    return Status::InvalidArgument(where + "features is empty (need at least one row and column)");
  }
  if (features.rows > kMaxRows) {
    return Status::ResourceExhausted(where + "features has " + std::to_string(features.rows) +
                                     " rows, more than the limit " + std::to_string(kMaxRows));
  }
  if (targets.size() != static_cast<std::size_t>(features.rows)) {
    return Status::InvalidArgument(where + "targets has " + std::to_string(targets.size()) +
                                   " values but features has " + std::to_string(features.rows) +
                                   " rows");
  }
  for (int r = 0; r < features.rows; ++r) {
    const float* row = features[r];
    for (int c = 0; c < features.cols; ++c) {
      if (!std::isfinite(row[c])) {
        return Status::InvalidArgument(where + "features(" + std::to_string(r) + ", " +
                                       std::to_string(c) + ") is not finite");
      }
    }
    if (!std::isfinite(targets[r])) {
      return Status::InvalidArgument(where + "targets[" + std::to_string(r) + "] is not finite");
    }
  }
  if (params.num_trees < 1 || params.num_trees > kMaxTrees) {
    return Status::InvalidArgument(where +
                                   "params.num_trees = " + std::to_string(params.num_trees) +
                                   " is outside [1, " + std::to_string(kMaxTrees) + "]");
  }
  if (params.min_leaf_size < 1) {
    return Status::InvalidArgument(
        where + "params.min_leaf_size = " + std::to_string(params.min_leaf_size) + " must be >= 1");
  }
  if (params.max_depth < 0) {
    return Status::InvalidArgument(
        where + "params.max_depth = " + std::to_string(params.max_depth) + " must be >= 0");
  }
  if (params.threads < 0) {
    return Status::InvalidArgument(where + "params.threads = " + std::to_string(params.threads) +
                                   " must be >= 0");
  }
  const double draws = params.sample_fraction * features.rows;
  if (!std::isfinite(params.sample_fraction) || params.sample_fraction <= 0.0 ||
      draws > static_cast<double>(kMaxRows)) {
    return Status::InvalidArgument(
        where + "params.sample_fraction = " + std::to_string(params.sample_fraction) +
        " must be > 0 and give at most " + std::to_string(kMaxRows) + " bootstrap draws");
  }
  return Status::Ok();
}

TreeSettings ResolveSettings(const ForestParams& params, int num_features, int rows) {
  TreeSettings settings;
  settings.mtry = params.max_features <= 0 ? std::max(1, num_features / 3)
                                           : std::min(params.max_features, num_features);
  settings.min_leaf_size = params.min_leaf_size;
  settings.max_depth = params.max_depth;
  settings.bootstrap_size =
      std::max(1, static_cast<int>(std::llround(params.sample_fraction * rows)));
  return settings;
}

// Each tree's stream depends only on (seed, tree index): results do not depend on threading.
std::uint64_t TreeSeed(std::uint64_t seed, int tree) {
  return SplitMix64::Mix(SplitMix64::Mix(seed) + 0x9E3779B97F4A7C15ULL * (tree + 1ULL));
}

int ResolveThreads(int requested, int num_trees) {
  int threads = requested > 0 ? requested : static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(threads, 1, num_trees);
}

}  // namespace

Result<RandomForest> RandomForest::Fit(const cv::Mat1f& features, const std::vector<float>& targets,
                                       const ForestParams& params) {
  if (Status status = ValidateTrainingInput(features, targets, params); !status.ok()) {
    return status;
  }
  const TreeSettings settings = ResolveSettings(params, features.cols, features.rows);
  const PresortedTrainingSet data = PresortedTrainingSet::Build(features, targets);

  std::vector<std::vector<Node>> trees(params.num_trees);
  std::atomic<int> next_tree{0};
  auto worker = [&]() {
    ForestTreeBuilder builder(data, settings);
    for (int t = next_tree++; t < params.num_trees; t = next_tree++) {
      trees[t] = builder.Build(TreeSeed(params.seed, t));
    }
  };
  const int num_threads = ResolveThreads(params.threads, params.num_trees);
  {
    std::vector<std::jthread> pool;
    for (int i = 1; i < num_threads; ++i) pool.emplace_back(worker);
    worker();
  }  // jthreads join here

  long long total_nodes = 0;
  for (const std::vector<Node>& tree : trees) total_nodes += static_cast<long long>(tree.size());
  if (total_nodes > kMaxNodes) {
    return Status::ResourceExhausted("RandomForest::Fit: the forest has " +
                                     std::to_string(total_nodes) + " nodes, more than " +
                                     std::to_string(kMaxNodes));
  }
  RandomForest forest;
  forest.num_features_ = features.cols;
  forest.nodes_.reserve(static_cast<std::size_t>(total_nodes));
  forest.tree_roots_.reserve(trees.size());
  for (const std::vector<Node>& tree : trees) {
    const auto offset = static_cast<std::int32_t>(forest.nodes_.size());
    forest.tree_roots_.push_back(offset);
    for (Node node : tree) {
      if (node.feature >= 0) node.left += offset;
      forest.nodes_.push_back(node);
    }
  }
  forest.PackForPrediction();
  return forest;
}

Result<RandomForest> RandomForest::Join(const std::vector<RandomForest>& parts) {
  RandomForest joined;
  long long total_nodes = 0;
  for (const RandomForest& part : parts) {
    if (part.empty()) continue;
    if (joined.num_features_ != 0 && part.num_features_ != joined.num_features_) {
      return Status::InvalidArgument("RandomForest::Join: a part has " +
                                     std::to_string(part.num_features_) + " features, another " +
                                     std::to_string(joined.num_features_));
    }
    joined.num_features_ = part.num_features_;
    total_nodes += part.num_nodes();
  }
  if (total_nodes > kMaxNodes) {
    return Status::ResourceExhausted("RandomForest::Join: the forest would have " +
                                     std::to_string(total_nodes) + " nodes, more than " +
                                     std::to_string(kMaxNodes));
  }
  joined.nodes_.reserve(static_cast<std::size_t>(total_nodes));
  for (const RandomForest& part : parts) {
    const auto offset = static_cast<std::int32_t>(joined.nodes_.size());
    for (const std::int32_t root : part.tree_roots_) joined.tree_roots_.push_back(root + offset);
    for (Node node : part.nodes_) {
      if (node.feature >= 0) node.left += offset;
      joined.nodes_.push_back(node);
    }
  }
  joined.PackForPrediction();
  return joined;
}

float RandomForest::Predict(const float* row) const {
  if (tree_roots_.empty()) return 0.f;
  double sum = 0.0;
  for (const std::int32_t root : tree_roots_) {
    std::int32_t i = root;
    while (nodes_[i].feature >= 0) {
      const Node& node = nodes_[i];
      i = node.left + (row[node.feature] > node.value ? 1 : 0);
    }
    sum += nodes_[i].value;
  }
  return static_cast<float>(sum / static_cast<double>(tree_roots_.size()));
}

void RandomForest::PackForPrediction() {
  compact_ = CompactForest::Build(nodes_, tree_roots_, num_features_);
}

int RandomForest::PredictionBlockRows() const {
  // A block walks one tree for all its rows, then the next tree. Loading a tree into cache costs
  // random misses; streaming the block's rows through once more costs prefetched sequential
  // reads. So the block's row bytes are made a multiple of a tree's bytes: big trees (the
  // 200-tree proposal regressors, ~190 KiB packed per tree) get blocks of ~45 000 rows, small
  // ones (the 8-tree pixel forest, ~50 KiB) ~6 000, which keeps those rows in L2 across trees.
  // The factor was tuned with tests/bench/bench_forest_predict.cc.
  const double node_bytes = compact_.empty() ? sizeof(Node) : compact_.bytes_per_node();
  const double tree_bytes = static_cast<double>(nodes_.size()) * node_bytes /
                            static_cast<double>(std::max<std::size_t>(1, tree_roots_.size()));
  const double row_bytes = static_cast<double>(num_features_) * sizeof(float) +
                           sizeof(const float*) + sizeof(double);  // row, its pointer and sum
  const double rows = kBlockRowBytesPerTreeByte * tree_bytes / row_bytes;
  return static_cast<int>(std::clamp(rows, static_cast<double>(kMinBlockRows), 1e9));
}

void RandomForest::AccumulateTrees(const float* const* rows, int count, int tree_begin,
                                   int tree_end, double* sums) const {
  // Blocks of rows walk one tree after another so a tree stays in cache across the block.
  const int rows_per_block = PredictionBlockRows();
  for (int start = 0; start < count; start += rows_per_block) {
    const int block = std::min(count - start, rows_per_block);
    const float* const* block_rows = rows + start;
    double* const block_sums = sums + start;
    if (!compact_.empty()) {
      compact_.AccumulateLeafValues(block_rows, block, block_sums, tree_begin, tree_end);
      continue;
    }
    // Too many nodes to pack: walk the stored nodes (same order, same sums).
    for (int tree = tree_begin; tree < tree_end; ++tree) {
      for (int r = 0; r < block; ++r) {
        std::int32_t i = tree_roots_[tree];
        while (nodes_[i].feature >= 0) {
          const Node& node = nodes_[i];
          i = node.left + (block_rows[r][node.feature] > node.value ? 1 : 0);
        }
        block_sums[r] += nodes_[i].value;
      }
    }
  }
}

void RandomForest::PredictRows(const float* const* rows, int count, float* out) const {
  // Per row the sum runs over trees in the same order as Predict: results are identical.
  std::vector<double> sums(static_cast<std::size_t>(count), 0.0);
  AccumulateTrees(rows, count, 0, num_trees(), sums.data());
  const auto trees = static_cast<double>(tree_roots_.size());
  for (int r = 0; r < count; ++r) out[r] = static_cast<float>(sums[r] / trees);
}

void RandomForest::AccumulateTreeRange(const cv::Mat1f& features, int tree_begin, int tree_end,
                                       double* sums) const {
  if (features.rows <= 0 || features.cols != num_features_) return;
  std::vector<const float*> rows(static_cast<std::size_t>(features.rows));
  for (int r = 0; r < features.rows; ++r) rows[r] = features[r];
  AccumulateTrees(rows.data(), features.rows, std::max(tree_begin, 0),
                  std::min(tree_end, num_trees()), sums);
}

namespace {

// The rows a piecewise walk still goes on with: their features, sums so far and row indices.
struct RowsGoingOn {
  std::vector<const float*> rows;
  std::vector<double> sums;
  std::vector<int> index;
};

// The screening step: rows whose mean over the first `trees` trees is at most `bound` stop with
// it (written to values); the others stay, in order, with their sums.
void StopRowsAtOrUnder(RowsGoingOn& walk, int trees, float bound, std::vector<float>& values) {
  std::size_t kept = 0;
  for (std::size_t r = 0; r < walk.rows.size(); ++r) {
    const float mean = static_cast<float>(walk.sums[r] / static_cast<double>(trees));
    if (mean <= bound) {
      values[walk.index[r]] = mean;
      continue;
    }
    walk.rows[kept] = walk.rows[r];
    walk.sums[kept] = walk.sums[r];
    walk.index[kept] = walk.index[r];
    ++kept;
  }
  walk.rows.resize(kept);
  walk.sums.resize(kept);
  walk.index.resize(kept);
}

}  // namespace

void RandomForest::AccumulateOnThreads(const std::vector<const float*>& rows, int tree_begin,
                                       int tree_end, std::vector<double>& sums, int threads) const {
  const int count = static_cast<int>(rows.size());
  const int shares =
      std::clamp(count / ForestWalkOptions::kMinRowsPerThread, 1, std::max(1, threads));
  const auto walk_share = [&](int p) {
    const int begin = count * p / shares, end = count * (p + 1) / shares;
    AccumulateTrees(rows.data() + begin, end - begin, tree_begin, tree_end, sums.data() + begin);
  };
  if (shares == 1) return walk_share(0);
  cv::parallel_for_(cv::Range(0, shares), [&](const cv::Range& range) {
    for (int p = range.start; p < range.end; ++p) walk_share(p);
  });
}

ForestWalk RandomForest::PredictBatchScreened(const cv::Mat1f& features,
                                              const ForestWalkOptions& options) const {
  ForestWalk out;
  if (features.rows <= 0) {
    out.trees = num_trees();  // nothing to walk: no tree is left out
    return out;
  }
  if (tree_roots_.empty()) {
    out.values.assign(static_cast<std::size_t>(features.rows), 0.f);
    return out;
  }
  if (features.cols != num_features_) return out;
  const int trees = num_trees();
  const bool screened = options.screening.trees > 0 && options.screening.trees < trees;
  const int per_piece = options.trees_per_piece > 0 ? options.trees_per_piece : trees;
  const auto count = static_cast<std::size_t>(features.rows);
  out.values.assign(count, 0.f);
  RowsGoingOn walk{std::vector<const float*>(count), std::vector<double>(count, 0.0),
                   std::vector<int>(count)};
  for (int r = 0; r < features.rows; ++r) walk.rows[r] = features[r];
  std::iota(walk.index.begin(), walk.index.end(), 0);
  // Pieces add in tree order to the rows' sums, so however the walk is cut the sums are one
  // walk's (AccumulateTrees); a row that stops at the screening keeps its mean over those trees.
  while (out.trees < trees) {
    const int first = out.trees;
    const int last =
        std::min(trees, first == 0 && screened ? options.screening.trees : first + per_piece);
    AccumulateOnThreads(walk.rows, first, last, walk.sums, options.threads);
    out.trees = last;
    if (first == 0 && screened) {
      StopRowsAtOrUnder(walk, last, options.screening.final_at_most, out.values);
    }
    if (std::chrono::steady_clock::now() >= options.deadline) break;
  }
  const auto walked = static_cast<double>(out.trees);
  for (std::size_t k = 0; k < walk.index.size(); ++k) {
    out.values[walk.index[k]] = static_cast<float>(walk.sums[k] / walked);
  }
  return out;
}

std::vector<float> RandomForest::PredictBatch(const cv::Mat1f& features) const {
  if (features.rows <= 0) return {};
  if (tree_roots_.empty()) return std::vector<float>(features.rows, 0.f);
  if (features.cols != num_features_) return {};
  std::vector<const float*> rows(features.rows);
  for (int r = 0; r < features.rows; ++r) rows[r] = features[r];
  std::vector<float> out(features.rows);
  PredictRows(rows.data(), features.rows, out.data());
  return out;
}

std::vector<float> RandomForest::PredictBatch(const cv::Mat1f& features,
                                              const std::vector<int>& subset) const {
  if (subset.empty()) return {};
  if (!tree_roots_.empty() && features.cols != num_features_) return {};
  std::vector<const float*> rows(subset.size());
  for (std::size_t k = 0; k < subset.size(); ++k) {
    if (subset[k] < 0 || subset[k] >= features.rows) return {};
    rows[k] = features[subset[k]];
  }
  if (tree_roots_.empty()) return std::vector<float>(subset.size(), 0.f);
  std::vector<float> out(subset.size());
  PredictRows(rows.data(), static_cast<int>(rows.size()), out.data());
  return out;
}

int RandomForest::CountLeaves(int tree) const {
  if (tree < 0 || tree >= num_trees()) return 0;
  int leaves = 0;
  std::vector<std::int32_t> stack{tree_roots_[tree]};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    if (node.feature < 0) {
      ++leaves;
    } else {
      stack.push_back(node.left);
      stack.push_back(node.left + 1);
    }
  }
  return leaves;
}

}  // namespace tod
