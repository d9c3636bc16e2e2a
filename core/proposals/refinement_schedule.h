// The side steps of Edge Boxes' refinement (ALGORITHM.md §4.2.7): steps start at
// floor(span * (1 - alpha) / (1 + alpha)) / 2 and halve until both are <= 2. Shared by the
// refinement itself and by the window admission, which needs how far refinement can move a side.
#pragma once

#include <algorithm>

namespace tod {

struct RefinementSchedule {
  static constexpr int kMaxIterations = 32;  // steps halve: a 2^31 span needs fewer
  int count = 0;
  int row_step[kMaxIterations] = {};
  int col_step[kMaxIterations] = {};
  int row_reach = 0;  // sum of the row steps: the most a top or bottom side can move
  int col_reach = 0;
};

// For a window with inclusive spans (r1 - r0, c1 - c0); `ratio` = (1 - alpha) / (1 + alpha).
inline RefinementSchedule ScheduleRefinement(int row_span, int col_span, float ratio) {
  RefinementSchedule s;
  int row_step = static_cast<int>(static_cast<float>(row_span) * ratio);
  int col_step = static_cast<int>(static_cast<float>(col_span) * ratio);
  while (s.count < RefinementSchedule::kMaxIterations) {
    row_step /= 2;
    col_step /= 2;
    if (row_step <= 2 && col_step <= 2) break;
    row_step = std::max(1, row_step);
    col_step = std::max(1, col_step);
    s.row_step[s.count] = row_step;
    s.col_step[s.count] = col_step;
    s.row_reach += row_step;
    s.col_reach += col_step;
    ++s.count;
  }
  return s;
}

}  // namespace tod
