// Grows one regression tree of the forest (ALGORITHM.md §6.3) on a bootstrap sample.
//
// Speed comes from presorting: every feature's rows are sorted once per forest; per tree the
// bootstrap sample is laid out in that order (a counting pass, no sort), and every node keeps,
// for every feature, its samples as one contiguous, sorted segment. A split stably partitions
// those segments, so finding the exact best threshold of a feature is one linear scan.
// One builder owns the scratch memory of one worker thread and is reused across trees.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/forest/random_forest.h"
#include "core/forest/split_mix.h"

namespace tod {

// The training set with, per feature, the row indices sorted by ascending value (ties by row).
struct PresortedTrainingSet {
  const cv::Mat1f* features = nullptr;          // rows x num_features, all finite
  const std::vector<float>* targets = nullptr;  // one per row, all finite
  std::vector<std::vector<std::int32_t>> rows_by_feature;

  int rows() const { return features->rows; }
  int num_features() const { return features->cols; }
  static PresortedTrainingSet Build(const cv::Mat1f& features, const std::vector<float>& targets);
};

// Tree-growing settings after the forest's defaults are resolved.
struct TreeSettings {
  int mtry = 1;            // features evaluated per split (non-constant ones)
  int min_leaf_size = 1;   // minimum bootstrap samples in every leaf
  int max_depth = 0;       // 0 = unlimited
  int bootstrap_size = 1;  // draws with replacement per tree
};

class ForestTreeBuilder {
 public:
  using Node = RandomForest::Node;

  ForestTreeBuilder(const PresortedTrainingSet& data, const TreeSettings& settings);

  // The nodes of one tree, root first, child indices relative to the returned vector.
  // Depends only on the data, the settings and tree_seed.
  std::vector<Node> Build(std::uint64_t tree_seed);

 private:
  struct Split {
    int feature = -1;
    int left_count = 0;
    float threshold = 0.f;
    double score = 0.0;  // sum_L^2 / n_L + sum_R^2 / n_R; larger = lower squared error
  };

  void DrawBootstrap(SplitMix64& rng);
  Split FindBestSplit(int begin, int end, double target_sum, SplitMix64& rng);
  void Partition(int begin, int end, const Split& split);

  const PresortedTrainingSet& data_;
  TreeSettings settings_;
  int slots_ = 0;  // bootstrap_size: one slot per draw (a row drawn twice has two slots)

  std::vector<std::int32_t> draws_per_row_;
  std::vector<float> slot_target_;
  // num_features x slots_: per feature, the slots of each node in ascending value order,
  // with their values alongside (no random access into the feature matrix while scanning).
  std::vector<std::int32_t> sorted_slots_;
  std::vector<float> sorted_values_;
  std::vector<std::uint8_t> goes_left_;  // per slot, valid during one Partition
  std::vector<std::int32_t> scratch_slots_;
  std::vector<float> scratch_values_;
  std::vector<int> feature_order_;
};

// Threshold strictly between two consecutive distinct values, as close to their midpoint as
// float allows: every x <= lower goes left and every x >= upper goes right.
float MidpointThreshold(float lower, float upper);

}  // namespace tod
