#include "core/proposals/window_admission.h"

#include <algorithm>
#include <cmath>

namespace tod {
namespace {

// Closed ranges [lo, hi] and [a, b] overlap.
bool Overlaps(double lo, double hi, double a, double b) { return lo <= b && hi >= a; }

}  // namespace

RowRanges WindowAdmission::AdmittedTops(int width, int height, RefinementReach reach,
                                        int limit) const {
  if (!filter_.enabled) return {{0, limit}};
  // Every size a refined window can have; the area range treats h and w independently, which
  // only admits more.
  const double h_lo = std::max(0, height - 2 * reach.rows), h_hi = height + 2 * reach.rows;
  const double w_lo = std::max(0, width - 2 * reach.cols), w_hi = width + 2 * reach.cols;
  RowRanges ranges;
  for (const SizeBand& band : filter_.bands) {
    if (!Overlaps(h_lo, h_hi, band.h_min, band.h_max) ||
        !Overlaps(w_lo, w_hi, band.w_min, band.w_max) ||
        !Overlaps(h_lo * w_lo, h_hi * w_hi, band.area_min, band.area_max)) {
      continue;
    }
    // Centre row of the refined box (image rows): origin + t + height / 2, moved by at most
    // reach.rows; it must fall in the band's open interval. One extra row on each side keeps
    // the integer conversion on the safe side.
    const double centre_offset = origin_y_ + 0.5 * height;
    const double first = band.center_y_min - centre_offset - reach.rows;
    const double last = band.center_y_max - centre_offset + reach.rows;
    const int begin = std::max(0, static_cast<int>(std::floor(first)) - 1);
    const int end = std::min(limit, static_cast<int>(std::ceil(last)) + 2);
    if (begin < end) ranges.emplace_back(begin, end);
  }
  std::sort(ranges.begin(), ranges.end());
  RowRanges merged;
  for (const auto& r : ranges) {
    if (!merged.empty() && r.first <= merged.back().second) {
      merged.back().second = std::max(merged.back().second, r.second);
    } else {
      merged.push_back(r);
    }
  }
  return merged;
}

}  // namespace tod
