// Which sliding windows can still end as a box the size filter keeps (ALGORITHM.md §4.3), so
// that the scan scores only those. Refinement (§4.2.7) moves each side of a window by at most
// a known reach, so a window whose every refined form fails the filter cannot contribute a kept
// box and is skipped. The filter itself still runs on the output.
#pragma once

#include <utility>
#include <vector>

#include "core/proposals/size_filter.h"

namespace tod {

// How far refinement can move each side of a window (RefinementSchedule::*_reach; 0 when
// refinement is off).
struct RefinementReach {
  int rows = 0;
  int cols = 0;
};

// Half-open ranges [begin, end) of window top rows, ascending and disjoint.
using RowRanges = std::vector<std::pair<int, int>>;

class WindowAdmission {
 public:
  // `filter` is in full-image coordinates; the region map's row 0 is image row origin_y (the
  // bands constrain sizes and centre rows only, so columns need no offset).
  WindowAdmission(SizeFilter filter, int origin_y)
      : filter_(std::move(filter)), origin_y_(origin_y) {}

  // Tops t (region rows) at which a window covering rows [t, t + height - 1] and `width`
  // columns, whose sides refinement moves by at most `reach`, may end as a kept box. A window
  // the filter cannot reject at any top (a disabled filter) gets [0, limit).
  RowRanges AdmittedTops(int width, int height, RefinementReach reach, int limit) const;

 private:
  SizeFilter filter_;
  int origin_y_ = 0;
};

}  // namespace tod
