// Greedy NMS with log-area bins (ALGORITHM.md §4.2.8). Exact: IoU(a, b) > t implies
// min(area) / max(area) > t, i.e. |log area_a - log area_b| < log(1 / t), so with bins of width
// log(1 / t) two boxes that can suppress each other are never more than one bin apart.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/proposals/edge_box_scorer.h"

namespace tod {
namespace {

class AreaBins {
 public:
  explicit AreaBins(float iou_threshold) {
    // Bins only help for thresholds in (0, 1); otherwise a single bin is plain greedy NMS.
    if (iou_threshold > 0.f && iou_threshold < 1.f) {
      log_step_ = std::log(1.0 / static_cast<double>(iou_threshold));
    }
    bins_.resize(log_step_ > 0.0 ? kBinCount : 1);
  }
  int BinOf(const Box& b) const {
    if (log_step_ <= 0.0 || b.area() <= 0) return 0;
    const double bin = std::floor(std::log(static_cast<double>(b.area())) / log_step_);
    return static_cast<int>(std::clamp(bin, 0.0, static_cast<double>(kBinCount - 1)));
  }
  int size() const { return static_cast<int>(bins_.size()); }
  std::vector<Box>& operator[](int i) { return bins_[i]; }

 private:
  static constexpr int kBinCount = 4096;  // log(area) / log(1/t) stays far below this
  double log_step_ = 0.0;
  std::vector<std::vector<Box>> bins_;
};

}  // namespace

std::vector<ScoredBox> NonMaximumSuppression(std::vector<ScoredBox> boxes, float iou_threshold,
                                             int max_boxes) {
  std::vector<ScoredBox> kept;
  if (boxes.empty() || max_boxes <= 0) return kept;
  // Order: score descending, then input order (deterministic under ties). Sorting all boxes is
  // wasteful when max_boxes is reached early, so select and sort growing chunks from the front.
  std::vector<int> order(boxes.size());
  std::iota(order.begin(), order.end(), 0);
  const auto before = [&boxes](int a, int b) {
    return boxes[a].score > boxes[b].score || (boxes[a].score == boxes[b].score && a < b);
  };
  AreaBins bins(iou_threshold);
  size_t done = 0;
  size_t chunk = std::max<size_t>(1024, 4 * static_cast<size_t>(max_boxes));
  while (done < order.size() && static_cast<int>(kept.size()) < max_boxes) {
    const auto first = order.begin() + static_cast<std::ptrdiff_t>(done);
    const size_t take = std::min(chunk, order.size() - done);
    const auto last = first + static_cast<std::ptrdiff_t>(take);
    if (last != order.end()) std::nth_element(first, last, order.end(), before);
    std::sort(first, last, before);
    for (auto it = first; it != last && static_cast<int>(kept.size()) < max_boxes; ++it) {
      const ScoredBox& candidate = boxes[*it];
      const int bin = bins.BinOf(candidate.box);
      bool keep = true;
      for (int b = std::max(0, bin - 1); keep && b <= std::min(bins.size() - 1, bin + 1); ++b) {
        for (const Box& k : bins[b]) {
          if (BoxIoU(candidate.box, k) > iou_threshold) {
            keep = false;
            break;
          }
        }
      }
      if (!keep) continue;
      bins[bin].push_back(candidate.box);
      kept.push_back(candidate);
    }
    done += take;
    chunk *= 2;
  }
  return kept;
}

}  // namespace tod
