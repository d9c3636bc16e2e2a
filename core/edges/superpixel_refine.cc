#include "core/edges/superpixel_refine.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <utility>
#include <vector>

namespace tod {
namespace {

// Running sums of one label, so that means update in O(1) when a pixel moves. One cache line
// per label: every cost evaluation reads a neighbouring label's sums, and a 56-byte record
// would straddle two lines most of the time.
struct alignas(64) LabelSums {
  double count = 0.0;
  double x = 0.0;
  double y = 0.0;
  double c0 = 0.0;
  double c1 = 0.0;
  double c2 = 0.0;
  double inverse_count = 0.0;  // 1 / count (0 when empty): a division per move, not per cost

  void Add(double sign, int px, int py, const float* c) {
    count += sign;
    inverse_count = count > 0 ? 1.0 / count : 0.0;
    x += sign * px;
    y += sign * py;
    c0 += sign * c[0];
    c1 += sign * c[1];
    c2 += sign * c[2];
  }
  // Add(1.0, ...) without updating inverse_count (set it once the pixels are in).
  void Accumulate(int px, int py, const float* c) {
    count += 1.0;
    x += px;
    y += py;
    c0 += c[0];
    c1 += c[1];
    c2 += c[2];
  }
};
static_assert(sizeof(LabelSums) == 64);

// Renumbers `labels` in place to 0..n-1 in order of first appearance, carrying the sums of every
// label (if any yet) along bit for bit, and keeps `original_id` (original id of every current one)
// up to date. The refinement only compares labels for equality and indexes the sums with them, so
// it makes the same moves on the renumbered map; what changes is that the sums of the labels in use
// sit next to each other instead of being spread over an array as large as the largest id: at half
// resolution most of the one-pixel labels die in the first sweeps, and at full resolution the
// ~10^4 labels carry ids up to ~3·10^5.
void RenumberDensely(std::vector<int>& labels, std::vector<LabelSums>& sums,
                     std::vector<int>& original_id) {
  std::vector<int> dense_id(original_id.size(), -1);
  std::vector<int> dense_original;
  for (int& label : labels) {
    int& id = dense_id[label];
    if (id < 0) {
      id = static_cast<int>(dense_original.size());
      dense_original.push_back(original_id[label]);
    }
    label = id;
  }
  if (!sums.empty()) {
    std::vector<LabelSums> dense_sums(dense_original.size());
    for (size_t old = 0; old < dense_id.size(); ++old) {
      if (dense_id[old] >= 0) dense_sums[dense_id[old]] = sums[old];
    }
    sums = std::move(dense_sums);
  }
  original_id = std::move(dense_original);
}

}  // namespace

StickyWeights StickyWeightsFor(int k, double alpha, double beta) {
  StickyWeights w;
  w.size = k * alpha / 1e4;
  w.position = alpha / 1e4;
  w.edge = (1.0 - alpha) * beta;
  w.colour = (1.0 - alpha) * (1.0 - beta);
  return w;
}

namespace {

// The state one refinement works on and the move of one pixel (ALGORITHM.md §3.2(1)).
class StickyRefiner {
 public:
  StickyRefiner(const StickyImage& image, const StickyWeights& weights, std::vector<int>& labels)
      : image_(image), weights_(weights), labels_(labels) {}

  std::vector<LabelSums>& sums() { return sums_; }

  // Whether pixel i has a 4-neighbour of another label (only such pixels can move), decided from
  // the labels alone, before any edge value is loaded.
  bool OnBorder(int x, int y) const {
    const size_t i = static_cast<size_t>(y) * image_.width + x;
    const int own = labels_[i];
    return (x > 0 && labels_[i - 1] != own) || (y > 0 && labels_[i - image_.width] != own) ||
           (x + 1 < image_.width && labels_[i + 1] != own) ||
           (y + 1 < image_.height && labels_[i + image_.width] != own);
  }

  // Moves the border pixel (x, y) to the neighbouring label of least cost (ties go to its own
  // label, then to the earliest neighbour in the order left, up, right, down); true if it moved.
  bool Move(int x, int y) {
    const int width = image_.width;
    const size_t i = static_cast<size_t>(y) * width + x;
    const int own = labels_[i];
    std::array<int, 4> nb_label;
    std::array<float, 4> nb_edge;
    int nb_count = 0;
    auto push = [&](size_t j) {
      nb_label[nb_count] = labels_[j];
      nb_edge[nb_count] = image_.edge[j];
      ++nb_count;
    };
    if (x > 0) push(i - 1);
    if (y > 0) push(i - width);
    if (x + 1 < width) push(i + 1);
    if (y + 1 < image_.height) push(i + width);

    const float* c = image_.colour + 3 * i;
    const double px = x;
    const double py = y;
    auto cost = [&](int t) {
      const LabelSums& s = sums_[t];
      // Size counted as if the pixel belonged to t (it already does when t is its own label):
      // with every pixel its own label initially this is what lets singletons merge.
      const double n = s.count + (t == own ? 0.0 : 1.0);
      const double inv = s.inverse_count;
      const double dx = px - s.x * inv;
      const double dy = py - s.y * inv;
      const double d0 = c[0] - s.c0 * inv;
      const double d1 = c[1] - s.c1 * inv;
      const double d2 = c[2] - s.c2 * inv;
      // e_t: weakest edge among the neighbours that would be across a boundary from the pixel if
      // it took label t; no such neighbour means no boundary at all, rewarded as the strongest
      // neighbouring edge.
      float e_min = std::numeric_limits<float>::max();
      float e_max = 0.f;
      for (int k = 0; k < nb_count; ++k) {
        e_max = std::max(e_max, nb_edge[k]);
        if (nb_label[k] != t) e_min = std::min(e_min, nb_edge[k]);
      }
      const double e_t = e_min == std::numeric_limits<float>::max() ? e_max : e_min;
      return weights_.position * (dx * dx + dy * dy) +
             weights_.colour * (d0 * d0 + d1 * d1 + d2 * d2) - weights_.edge * e_t +
             weights_.size / n;
    };

    int best = own;
    double best_cost = cost(own);
    for (int k = 0; k < nb_count; ++k) {
      const int t = nb_label[k];
      if (t == own || t == best) continue;
      bool seen = false;
      for (int m = 0; m < k; ++m) seen |= nb_label[m] == t;
      if (seen) continue;
      const double ct = cost(t);
      if (ct < best_cost) {
        best_cost = ct;
        best = t;
      }
    }
    if (best == own) return false;
    sums_[own].Add(-1.0, x, y, c);
    sums_[best].Add(1.0, x, y, c);
    if (last_row_) {
      // One writer per label at a time (SweepChain), so a load and a store suffice.
      std::atomic<int>& last = last_row_[best];
      if (last.load(std::memory_order_relaxed) < y) last.store(y, std::memory_order_relaxed);
    }
    labels_[i] = best;
    return true;
  }

  // One sweep in raster order (the reference order); returns the pixels moved.
  long long SweepRaster() {
    long long moved = 0;
    for (int y = 0; y < image_.height; ++y)
      for (int x = 0; x < image_.width; ++x)
        if (OnBorder(x, y)) moved += Move(x, y);
    return moved;
  }

  // `count` raster sweeps at once, each a few rows behind the one before it, with exactly the
  // moves of the sweeps one after the other (see RefineStickyLabels); returns the pixels each
  // moved.
  std::vector<long long> SweepChain(int count);

 private:
  // Sweep `index` of a chain, in raster order; publishes the rows it has finished in
  // done[index]. From index 1 on it waits until the sweeps ahead can no longer touch what it reads.
  long long SweepInChain(std::vector<std::atomic<int>>& done, int index);
  // The rows the sweep just ahead of sweep `index` has finished. The counters of the sweeps
  // further ahead are read too, so that what they wrote before those rows is visible here.
  static int RowsAhead(const std::vector<std::atomic<int>>& done, int index);
  // Waits until the sweep just ahead has finished `rows` rows.
  void WaitForRows(const std::vector<std::atomic<int>>& done, int index, int rows) const;
  // Waits until every label the move of (x, y) reads lies above the two rows next to the sweep
  // just ahead (or that sweep is done): no sweep ahead can then read or change those labels.
  void WaitForLabels(const std::vector<std::atomic<int>>& done, int index, int x, int y) const;
  // The largest last_row_ among the labels of (x, y) and its 4-neighbours.
  int LastRowAround(int x, int y) const;

  const StickyImage& image_;
  const StickyWeights& weights_;
  std::vector<int>& labels_;
  std::vector<LabelSums> sums_;
  // Per label during SweepChain: a bound on the last row its pixels lie in (moves only raise it).
  std::unique_ptr<std::atomic<int>[]> last_row_;
};

std::vector<long long> StickyRefiner::SweepChain(int count) {
  last_row_ = std::make_unique<std::atomic<int>[]>(sums_.size());
  for (int y = 0; y < image_.height; ++y)
    for (int x = 0; x < image_.width; ++x)
      last_row_[labels_[static_cast<size_t>(y) * image_.width + x]].store(
          y, std::memory_order_relaxed);
  std::vector<std::atomic<int>> done(static_cast<size_t>(count));
  std::vector<long long> moved(static_cast<size_t>(count), 0);
  // A task takes its sweep when it starts, so every sweep a sweep waits for belongs to a task
  // that is running, and the first never waits: the chain cannot deadlock, however the pool
  // schedules (or serialises) the tasks.
  std::atomic<int> next{0};
  cv::parallel_for_(cv::Range(0, count), [&](const cv::Range& range) {
    for (int n = range.start; n < range.end; ++n) {
      const int sweep = next.fetch_add(1);
      moved[sweep] = SweepInChain(done, sweep);
    }
  });
  last_row_.reset();
  return moved;
}

long long StickyRefiner::SweepInChain(std::vector<std::atomic<int>>& done, int index) {
  long long moved = 0;
  for (int y = 0; y < image_.height; ++y) {
    // OnBorder reads the row below: the sweep ahead must be past it.
    if (index > 0) WaitForRows(done, index, std::min(image_.height, y + 2));
    for (int x = 0; x < image_.width; ++x) {
      if (!OnBorder(x, y)) continue;
      if (index > 0) WaitForLabels(done, index, x, y);
      moved += Move(x, y);
    }
    done[index].store(y + 1, std::memory_order_release);
    done[index].notify_one();  // the sweep behind, if it waits (cheap when nobody does)
  }
  return moved;
}

int StickyRefiner::RowsAhead(const std::vector<std::atomic<int>>& done, int index) {
  const int rows = done[index - 1].load(std::memory_order_acquire);
  for (int k = index - 2; k >= 0; --k) (void)done[k].load(std::memory_order_acquire);
  return rows;
}

void StickyRefiner::WaitForRows(const std::vector<std::atomic<int>>& done, int index,
                                int rows) const {
  for (int finished = RowsAhead(done, index); finished < rows; finished = RowsAhead(done, index)) {
    done[index - 1].wait(finished, std::memory_order_acquire);
  }
}

void StickyRefiner::WaitForLabels(const std::vector<std::atomic<int>>& done, int index, int x,
                                  int y) const {
  // The sweep just ahead has finished rows [0, d) and is at row d; every sweep further ahead is
  // further down (each waits for the rows below the one it is at). Their remaining moves read and
  // write only labels with a pixel in row d - 1 or below. A label whose pixels all lie in rows
  // <= d - 2 is not next to any pixel they have yet to visit, and a pixel only ever joins a
  // neighbour's label, so they never reach such a label again. The bounds a sweep raised before
  // finishing a row are visible once that row's counter is (release / acquire).
  for (;;) {
    const int finished = RowsAhead(done, index);
    if (finished >= image_.height || LastRowAround(x, y) <= finished - 2) return;
    // Blocks (after a short spin) until the sweep ahead finishes another row: on a machine
    // where the sweeps share a core, spinning would take its time from the sweep ahead.
    done[index - 1].wait(finished, std::memory_order_acquire);
  }
}

int StickyRefiner::LastRowAround(int x, int y) const {
  const size_t i = static_cast<size_t>(y) * image_.width + x;
  const auto last = [&](size_t j) { return last_row_[labels_[j]].load(std::memory_order_relaxed); };
  int reach = last(i);
  if (x > 0) reach = std::max(reach, last(i - 1));
  if (y > 0) reach = std::max(reach, last(i - image_.width));
  if (x + 1 < image_.width) reach = std::max(reach, last(i + 1));
  if (y + 1 < image_.height) reach = std::max(reach, last(i + image_.width));
  return reach;
}

}  // namespace

int RefineStickyLabels(const StickyImage& image, const StickyWeights& weights, int iterations,
                       std::vector<int>& labels) {
  const int width = image.width;
  const int height = image.height;
  if (width <= 0 || height <= 0 || labels.empty()) return 0;
  StickyRefiner refiner(image, weights, labels);
  std::vector<LabelSums>& sums = refiner.sums();
  const int max_label = *std::max_element(labels.begin(), labels.end());
  std::vector<int> original_id(static_cast<size_t>(max_label) + 1);
  for (size_t id = 0; id < original_id.size(); ++id) original_id[id] = static_cast<int>(id);
  RenumberDensely(labels, sums, original_id);
  sums.resize(original_id.size());
  // The sums as Add would leave them, with the one division per label done once at the end (the
  // same value: 1 / count of the final count) instead of once per pixel.
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      sums[labels[i]].Accumulate(x, y, image.colour + 3 * i);
    }
  }
  for (LabelSums& s : sums) s.inverse_count = s.count > 0 ? 1.0 / s.count : 0.0;

  // The raster order on several threads: as many sweeps at once, each rows behind the one before.
  const int chain = std::max(1, cv::getNumThreads());
  int sweeps = 0;
  const size_t pixels = static_cast<size_t>(width) * height;
  for (int iter = 0; iter < iterations;) {
    // A sweep over (nearly) one label per pixel runs alone: it empties most labels, and the
    // compaction after it shrinks the running sums the next sweeps read at every move from one
    // per pixel (29 MB at half resolution on a real frame) to one per superpixel. Chained behind
    // it, the second sweep read the uncompacted sums, and the pair took longer than the two
    // sweeps one after the other (18 against 16 ms, docs/findings.md#opencv-calls-on-one-thread).
    const bool mostly_singletons = 2 * sums.size() > pixels;
    const int count = mostly_singletons ? 1 : std::min(chain, iterations - iter);
    if (count > 1) {
      // A sweep that moves nothing leaves the state as it found it, so every sweep after it moves
      // nothing either: the count is that of sweeps one after the other.
      const std::vector<long long> moved = refiner.SweepChain(count);
      const auto first_still = std::find(moved.begin(), moved.end(), 0LL) - moved.begin();
      sweeps += static_cast<int>(std::min<std::ptrdiff_t>(first_still + 1, count));
      if (first_still < count) break;
      iter += count;
    } else {
      ++sweeps;
      if (refiner.SweepRaster() == 0) break;
      ++iter;
    }
    if (iter < iterations) {
      // Compact once at least half of the labels have emptied (a pass over the labels, cheap
      // next to a sweep).
      const auto alive =
          std::count_if(sums.begin(), sums.end(), [](const LabelSums& s) { return s.count > 0; });
      if (2 * static_cast<size_t>(alive) <= sums.size()) RenumberDensely(labels, sums, original_id);
    }
  }
  for (int& label : labels) label = original_id[label];
  return sweeps;
}

}  // namespace tod
