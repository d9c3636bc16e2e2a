#include "core/training/training_folds.h"

#include <map>

namespace tod {

Result<FoldLayout> ParseFoldLayout(const std::string& name) {
  if (name == "blocks") return FoldLayout::kSequenceBlocks;
  if (name == "alternate") return FoldLayout::kAlternate;
  return Status::InvalidArgument("--fold-layout must be blocks or alternate, got '" + name + "'");
}

const char* FoldLayoutName(FoldLayout layout) {
  return layout == FoldLayout::kSequenceBlocks ? "blocks" : "alternate";
}

std::vector<int> AssignFolds(int num_frames, const std::vector<int>& usable,
                             const std::vector<int>& classifier_frames, int folds,
                             FoldLayout layout, const std::vector<int>& source) {
  std::vector<int> fold_of(static_cast<std::size_t>(num_frames), -1);
  if (folds < 1) return fold_of;
  if (layout == FoldLayout::kSequenceBlocks) {
    std::map<int, std::vector<int>> by_source;  // usable positions of each dataset, in order
    for (int i : usable) by_source[source.empty() ? 0 : source[i]].push_back(i);
    for (const auto& [dataset, positions] : by_source) {
      const long long n = static_cast<long long>(positions.size());
      for (long long j = 0; j < n; ++j) fold_of[positions[j]] = static_cast<int>(j * folds / n);
    }
    return fold_of;
  }
  int next = 0;
  for (int i : classifier_frames) fold_of[i] = next++ % folds;
  next = 0;
  for (int i : usable)
    if (fold_of[i] < 0) fold_of[i] = next++ % folds;
  return fold_of;
}

}  // namespace tod
