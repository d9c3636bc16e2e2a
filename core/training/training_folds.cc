#include "core/training/training_folds.h"

#include <map>

namespace tod {

std::vector<int> AssignFolds(int num_frames, const std::vector<int>& usable, int folds,
                             const std::vector<int>& source) {
  std::vector<int> fold_of(static_cast<std::size_t>(num_frames), -1);
  if (folds < 1) return fold_of;
  std::map<int, std::vector<int>> by_source;  // usable positions of each dataset, in order
  for (int i : usable) by_source[source.empty() ? 0 : source[i]].push_back(i);
  for (const auto& [dataset, positions] : by_source) {
    const long long n = static_cast<long long>(positions.size());
    for (long long j = 0; j < n; ++j) fold_of[positions[j]] = static_cast<int>(j * folds / n);
  }
  return fold_of;
}

}  // namespace tod
