// Random-forest regression (ALGORITHM.md §6.3): bootstrap samples, mtry features tried per split,
// minimum leaf size, squared-error reduction, leaf = mean target, prediction = mean over trees.
// Also used as a probabilistic classifier by regressing 0/1 targets.
// Stored in a compact little-endian binary form that loads in milliseconds.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <vector>

#include <opencv2/core.hpp>

#include "core/base/status.h"

namespace tod {

struct ForestParams {
  int num_trees = 200;
  int max_features = 6;      // mtry; <= 0 means floor(num_features / 3), at least 1
  int min_leaf_size = 5;
  int max_depth = 0;         // 0 = unlimited
  double sample_fraction = 1.0;  // bootstrap size as a fraction of the training set
  std::uint64_t seed = 1;
  int threads = 0;           // 0 = hardware concurrency
};

class RandomForest {
 public:
  RandomForest() = default;
  // features: one row per sample (CV_32F); targets: one per row.
  static RandomForest Train(const cv::Mat1f& features, const std::vector<float>& targets,
                            const ForestParams& params);

  float Predict(const float* row) const;
  std::vector<float> PredictBatch(const cv::Mat1f& features) const;

  int num_features() const { return num_features_; }
  int num_trees() const { return static_cast<int>(tree_roots_.size()); }
  bool empty() const { return tree_roots_.empty(); }

  Status Save(std::ostream& out) const;
  // `what` names the source in error messages (e.g. the file path).
  static Result<RandomForest> Load(std::istream& in, const std::string& what);

 private:
  struct Node {
    std::int32_t feature = -1;  // -1 = leaf
    float threshold = 0.f;      // go left when x[feature] <= threshold
    std::int32_t left = -1;     // child indices into nodes_
    std::int32_t right = -1;
    float value = 0.f;          // leaf mean
  };
  int num_features_ = 0;
  std::vector<Node> nodes_;
  std::vector<std::int32_t> tree_roots_;
};

}  // namespace tod
