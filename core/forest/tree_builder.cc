#include "core/forest/tree_builder.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace tod {

PresortedTrainingSet PresortedTrainingSet::Build(const cv::Mat1f& features,
                                                 const std::vector<float>& targets) {
  PresortedTrainingSet set;
  set.features = &features;
  set.targets = &targets;
  set.rows_by_feature.resize(features.cols);
  std::vector<float> column(features.rows);
  for (int f = 0; f < features.cols; ++f) {
    for (int r = 0; r < features.rows; ++r) column[r] = features(r, f);
    std::vector<std::int32_t>& order = set.rows_by_feature[f];
    order.resize(features.rows);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&column](std::int32_t a, std::int32_t b) { return column[a] < column[b]; });
  }
  return set;
}

float MidpointThreshold(float lower, float upper) {
  const float mid =
      static_cast<float>((static_cast<double>(lower) + static_cast<double>(upper)) * 0.5);
  // Adjacent floats: the midpoint rounds to one of them; `upper` must still go right.
  return mid < upper ? mid : lower;
}

ForestTreeBuilder::ForestTreeBuilder(const PresortedTrainingSet& data, const TreeSettings& settings)
    : data_(data), settings_(settings), slots_(settings.bootstrap_size) {
  const std::size_t table = static_cast<std::size_t>(data.num_features()) * slots_;
  draws_per_row_.resize(data.rows());
  slot_target_.resize(slots_);
  sorted_slots_.resize(table);
  sorted_values_.resize(table);
  goes_left_.resize(slots_);
  scratch_slots_.resize(slots_);
  scratch_values_.resize(slots_);
  feature_order_.resize(data.num_features());
}

void ForestTreeBuilder::DrawBootstrap(SplitMix64& rng) {
  const int rows = data_.rows();
  std::fill(draws_per_row_.begin(), draws_per_row_.end(), 0);
  for (int i = 0; i < slots_; ++i) ++draws_per_row_[rng.Below(static_cast<std::uint32_t>(rows))];

  // Slots are numbered by row; first_slot doubles as the slot -> target table's filler.
  std::vector<std::int32_t> first_slot(rows);
  const std::vector<float>& targets = *data_.targets;
  std::int32_t next = 0;
  for (int r = 0; r < rows; ++r) {
    first_slot[r] = next;
    for (int c = 0; c < draws_per_row_[r]; ++c) slot_target_[next++] = targets[r];
  }
  // Lay out each feature's slots in presorted order: a counting pass instead of a sort.
  const cv::Mat1f& x = *data_.features;
  for (int f = 0; f < data_.num_features(); ++f) {
    std::int32_t* slots = &sorted_slots_[static_cast<std::size_t>(f) * slots_];
    float* values = &sorted_values_[static_cast<std::size_t>(f) * slots_];
    int pos = 0;
    for (const std::int32_t r : data_.rows_by_feature[f]) {
      const float value = x(r, f);
      for (int c = 0; c < draws_per_row_[r]; ++c) {
        slots[pos] = first_slot[r] + c;
        values[pos] = value;
        ++pos;
      }
    }
  }
}

ForestTreeBuilder::Split ForestTreeBuilder::FindBestSplit(int begin, int end, double target_sum,
                                                          SplitMix64& rng) {
  const int n = end - begin;
  const int min_leaf = settings_.min_leaf_size;
  const int num_features = data_.num_features();
  std::iota(feature_order_.begin(), feature_order_.end(), 0);

  Split best;
  best.score = -1.0;
  int evaluated = 0;
  // Features in random order (partial Fisher-Yates). As in scikit-learn, features constant in
  // the node do not count towards mtry, and the search goes on past mtry until some valid split
  // exists, so a node is a leaf only when no feature can split it.
  for (int k = 0; k < num_features; ++k) {
    if (evaluated >= settings_.mtry && best.feature >= 0) break;
    const int pick = k + static_cast<int>(rng.Below(static_cast<std::uint32_t>(num_features - k)));
    std::swap(feature_order_[k], feature_order_[pick]);
    const int f = feature_order_[k];
    const std::int32_t* slots = &sorted_slots_[static_cast<std::size_t>(f) * slots_];
    const float* values = &sorted_values_[static_cast<std::size_t>(f) * slots_];
    if (values[begin] == values[end - 1]) continue;
    ++evaluated;

    double left_sum = 0.0;
    for (int p = begin; p < begin + min_leaf - 1; ++p) left_sum += slot_target_[slots[p]];
    // Candidate cut after position p: left = [begin, p], right = (p, end).
    for (int p = begin + min_leaf - 1; p < end - min_leaf; ++p) {
      left_sum += slot_target_[slots[p]];
      if (values[p] == values[p + 1]) continue;
      const int left_count = p - begin + 1;
      const double right_sum = target_sum - left_sum;
      const double score =
          left_sum * left_sum / left_count + right_sum * right_sum / (n - left_count);
      if (score > best.score) {
        best.feature = f;
        best.left_count = left_count;
        best.threshold = MidpointThreshold(values[p], values[p + 1]);
        best.score = score;
      }
    }
  }
  return best;
}

void ForestTreeBuilder::Partition(int begin, int end, const Split& split) {
  const std::int32_t* split_slots =
      &sorted_slots_[static_cast<std::size_t>(split.feature) * slots_];
  const int cut = begin + split.left_count;
  for (int p = begin; p < cut; ++p) goes_left_[split_slots[p]] = 1;
  for (int p = cut; p < end; ++p) goes_left_[split_slots[p]] = 0;

  // Stable partition of every other feature's segment: left slots compact in place (the write
  // position never passes the read position), right slots go through scratch.
  for (int f = 0; f < data_.num_features(); ++f) {
    if (f == split.feature) continue;  // already ordered left | right
    std::int32_t* slots = &sorted_slots_[static_cast<std::size_t>(f) * slots_];
    float* values = &sorted_values_[static_cast<std::size_t>(f) * slots_];
    int write = begin;
    int spilled = 0;
    for (int p = begin; p < end; ++p) {
      if (goes_left_[slots[p]]) {
        slots[write] = slots[p];
        values[write] = values[p];
        ++write;
      } else {
        scratch_slots_[spilled] = slots[p];
        scratch_values_[spilled] = values[p];
        ++spilled;
      }
    }
    std::copy(scratch_slots_.begin(), scratch_slots_.begin() + spilled, slots + write);
    std::copy(scratch_values_.begin(), scratch_values_.begin() + spilled, values + write);
  }
}

std::vector<ForestTreeBuilder::Node> ForestTreeBuilder::Build(std::uint64_t tree_seed) {
  SplitMix64 rng(tree_seed);
  DrawBootstrap(rng);

  struct Pending {
    std::int32_t node;
    int begin;
    int end;
    int depth;
  };
  std::vector<Node> nodes(1);
  std::vector<Pending> stack{{0, 0, slots_, 0}};
  const std::int32_t* node_slots = sorted_slots_.data();  // feature 0's order: any will do
  while (!stack.empty()) {
    const Pending task = stack.back();
    stack.pop_back();
    const int n = task.end - task.begin;
    double sum = 0.0;
    float lowest = slot_target_[node_slots[task.begin]];
    float highest = lowest;
    for (int p = task.begin; p < task.end; ++p) {
      const float y = slot_target_[node_slots[p]];
      sum += y;
      lowest = std::min(lowest, y);
      highest = std::max(highest, y);
    }
    nodes[task.node].value = static_cast<float>(sum / n);

    const bool depth_exhausted = settings_.max_depth > 0 && task.depth >= settings_.max_depth;
    if (depth_exhausted || n < 2 * settings_.min_leaf_size || lowest == highest) continue;
    const Split split = FindBestSplit(task.begin, task.end, sum, rng);
    if (split.feature < 0) continue;

    Partition(task.begin, task.end, split);
    const auto left = static_cast<std::int32_t>(nodes.size());
    nodes[task.node].feature = split.feature;
    nodes[task.node].value = split.threshold;
    nodes[task.node].left = left;
    nodes.resize(nodes.size() + 2);
    const int cut = task.begin + split.left_count;
    stack.push_back({left + 1, cut, task.end, task.depth + 1});
    stack.push_back({left, task.begin, cut, task.depth + 1});
  }
  return nodes;
}

}  // namespace tod
