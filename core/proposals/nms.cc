// Greedy NMS with log-area bins and a position grid per bin (ALGORITHM.md §4.2.8). Both only
// skip kept boxes that provably cannot exceed the IoU threshold t in (0, 1):
//  * IoU(a, b) > t implies min(area) / max(area) > t, i.e. |log area_a - log area_b| < log(1 / t),
//    so with bins of width log(1 / t) two boxes that can suppress each other are never more than
//    one bin apart;
//  * IoU > t needs intersection > t * max(area), so the intersection width exceeds t * w_a and
//    t * w_b; with a left of b, x_b - x_a <= w_a - intersection width < (1 - t) w_a < (1 - t) / t
//    w_b. Hence |x_a - x_b| < (1 - t) / t * w of either box (rows likewise), and a candidate only
//    needs the grid cells within that radius of its top-left corner.
// With 10 000 kept boxes the grid turns the per-candidate scan of thousands of same-size boxes
// into a few cells.
#include <algorithm>
#include <bit>
#include <cmath>

#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/greedy_nms.h"

namespace tod {
namespace {

constexpr int kBinCount = 4096;  // log(area) / log(1/t) stays far below this
constexpr long long kMaxCells = 1 << 22;

// BoxIoU(a, b) > t for two non-empty boxes and t in (0, 1), without BoxIoU's division unless
// the ratio lies within a billionth of t. The same answer: intersection and union are exact
// integers, and the quotient's rounding (and that of t * union) is ~1e-16 relative. The division
// was a fifth of the NMS on real frames.
bool IoUAbove(const Box& a, const Box& b, double t) {
  const long long iw = static_cast<long long>(std::min(a.right(), b.right())) - std::max(a.x, b.x);
  if (iw <= 0) return false;
  const long long ih =
      static_cast<long long>(std::min(a.bottom(), b.bottom())) - std::max(a.y, b.y);
  if (ih <= 0) return false;
  const long long inter = iw * ih;
  const double needed = t * static_cast<double>(a.area() + b.area() - inter);
  const auto got = static_cast<double>(inter);
  if (got > needed * (1.0 + 1e-9)) return true;
  if (got < needed * (1.0 - 1e-9)) return false;
  return BoxIoU(a, b) > t;
}

}  // namespace

GreedyNms::GreedyNms(float iou_threshold, int max_boxes, int min_x, int min_y, int max_x, int max_y)
    : threshold_(iou_threshold),
      max_boxes_(max_boxes),
      min_x_(min_x),
      min_y_(min_y),
      max_x_(std::max(min_x, max_x)),
      max_y_(std::max(min_y, max_y)) {
  // The bounds only hold for thresholds in (0, 1); otherwise one flat list (plain greedy NMS).
  if (!(iou_threshold > 0.f && iou_threshold < 1.f)) return;
  log_step_ = std::log(1.0 / static_cast<double>(iou_threshold));
  // Suppressed() adds 2 px of slack for the rounding of the IoU division.
  radius_factor_ = (1.0 - iou_threshold) / iou_threshold;
  grids_.resize(kBinCount);
}

bool GreedyNms::Offer(const ScoredBox& box) {
  if (full() || Suppressed(box.box)) return false;
  Add(box.box);
  kept_.push_back(box);
  return true;
}

// Cells are a power of two wide, so a cell index is a shift: these run a dozen times per
// candidate, and 64-bit divisions made up a good part of the search. Any monotone map from
// offsets to cells keeps the search complete (a kept box within the radius lies in a cell
// between the cells of the radius' ends).
int GreedyNms::Grid::CellX(long long offset) const {
  return static_cast<int>(std::min<long long>(std::max(offset, 0LL) >> cell_shift, cols - 1));
}
int GreedyNms::Grid::CellY(long long offset) const {
  return static_cast<int>(std::min<long long>(std::max(offset, 0LL) >> cell_shift, rows - 1));
}

bool GreedyNms::Suppressed(const Box& candidate) const {
  if (grids_.empty()) {
    return std::any_of(flat_.begin(), flat_.end(),
                       [&](const Box& k) { return BoxIoU(candidate, k) > threshold_; });
  }
  if (candidate.empty()) return false;  // IoU 0 with everything
  const int bin = BinOf(candidate);
  const long long rx = static_cast<long long>(radius_factor_ * candidate.w) + 2;
  const long long ry = static_cast<long long>(radius_factor_ * candidate.h) + 2;
  const auto suppressed_in_cell = [&](const Grid& g, int gx, int gy) {
    for (int e = g.head[static_cast<size_t>(gx) * g.rows + gy]; e >= 0; e = entries_[e].next) {
      if (IoUAbove(candidate, entries_[e].box, threshold_)) return true;
    }
    return false;
  };
  // Most candidates are suppressed, and most often by a kept box of about their own size and
  // place: the candidate's own bin and cell are searched first, which ends most searches early.
  // (The answer does not depend on the order.)
  for (const int b : {bin, bin - 1, bin + 1}) {
    if (b < 0 || b >= kBinCount) continue;
    const Grid& g = grids_[b];
    if (g.head.empty()) continue;
    const int own_x = g.CellX(candidate.x - min_x_), own_y = g.CellY(candidate.y - min_y_);
    if (suppressed_in_cell(g, own_x, own_y)) return true;
    const int gx0 = g.CellX(candidate.x - rx - min_x_), gx1 = g.CellX(candidate.x + rx - min_x_);
    const int gy0 = g.CellY(candidate.y - ry - min_y_), gy1 = g.CellY(candidate.y + ry - min_y_);
    for (int gx = gx0; gx <= gx1; ++gx) {
      for (int gy = gy0; gy <= gy1; ++gy) {
        if ((gx != own_x || gy != own_y) && suppressed_in_cell(g, gx, gy)) return true;
      }
    }
  }
  return false;
}

void GreedyNms::Add(const Box& kept) {
  if (grids_.empty()) {
    flat_.push_back(kept);
    return;
  }
  if (kept.empty()) return;  // suppresses nothing
  const int bin = BinOf(kept);
  Grid& g = grids_[bin];
  if (g.head.empty()) g = MakeGrid(bin);
  const size_t cell =
      static_cast<size_t>(g.CellX(kept.x - min_x_)) * g.rows + g.CellY(kept.y - min_y_);
  entries_.push_back({kept, g.head[cell]});
  g.head[cell] = static_cast<int>(entries_.size()) - 1;
}

int GreedyNms::BinOf(const Box& b) const {
  const double bin = std::floor(std::log(static_cast<double>(b.area())) / log_step_);
  return static_cast<int>(std::clamp(bin, 0.0, static_cast<double>(kBinCount - 1)));
}

// Cells of about half the side of a square box of the bin's smallest area (rounded down to a
// power of two): a candidate then scans two to four cells per axis.
GreedyNms::Grid GreedyNms::MakeGrid(int bin) const {
  Grid g;
  const long long wanted =
      std::max(2LL, static_cast<long long>(0.5 * std::exp(0.5 * bin * log_step_)));
  g.cell_shift = std::bit_width(static_cast<unsigned long long>(wanted)) - 1;  // round down
  const long long span_x = static_cast<long long>(max_x_) - min_x_ + 1;
  const long long span_y = static_cast<long long>(max_y_) - min_y_ + 1;
  while (((span_x >> g.cell_shift) + 1) * ((span_y >> g.cell_shift) + 1) > kMaxCells) {
    ++g.cell_shift;
  }
  g.cols = static_cast<int>((span_x >> g.cell_shift) + 1);
  g.rows = static_cast<int>((span_y >> g.cell_shift) + 1);
  g.head.assign(static_cast<size_t>(g.cols) * g.rows, -1);
  return g;
}

std::vector<ScoredBox> NonMaximumSuppression(std::vector<ScoredBox> boxes, float iou_threshold,
                                             int max_boxes) {
  // A NaN score has no place in the order (and would break the sort): such boxes are dropped.
  std::erase_if(boxes, [](const ScoredBox& b) { return std::isnan(b.score); });
  if (boxes.empty() || max_boxes <= 0) return {};
  int min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  bool first = true;
  for (const ScoredBox& b : boxes) {
    if (b.box.empty()) continue;
    min_x = first ? b.box.x : std::min(min_x, b.box.x);
    min_y = first ? b.box.y : std::min(min_y, b.box.y);
    max_x = first ? b.box.x : std::max(max_x, b.box.x);
    max_y = first ? b.box.y : std::max(max_y, b.box.y);
    first = false;
  }
  GreedyNms nms(iou_threshold, max_boxes, min_x, min_y, max_x, max_y);
  // Order: score descending, then input order (deterministic under ties). The keys carry their
  // score so that comparisons need no lookup into `boxes` (a cache miss each in a large set).
  // Sorting all boxes is wasteful when max_boxes is reached early, so select and sort growing
  // chunks from the front.
  struct Key {
    float score;
    int index;
  };
  std::vector<Key> order(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) order[i] = {boxes[i].score, static_cast<int>(i)};
  const auto before = [](const Key& a, const Key& b) {
    return a.score > b.score || (a.score == b.score && a.index < b.index);
  };
  size_t done = 0;
  size_t chunk = std::max<size_t>(1024, 4 * static_cast<size_t>(max_boxes));
  while (done < order.size() && !nms.full()) {
    const auto first_it = order.begin() + static_cast<std::ptrdiff_t>(done);
    const size_t take = std::min(chunk, order.size() - done);
    const auto last = first_it + static_cast<std::ptrdiff_t>(take);
    if (last != order.end()) std::nth_element(first_it, last, order.end(), before);
    std::sort(first_it, last, before);
    for (auto it = first_it; it != last && !nms.full(); ++it) nms.Offer(boxes[it->index]);
    done += take;
    chunk *= 2;
  }
  return nms.TakeKept();
}

}  // namespace tod
