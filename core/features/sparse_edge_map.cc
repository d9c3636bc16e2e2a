#include "core/features/sparse_edge_map.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

namespace tod {
namespace {

// Distinct positive values -> dense ids, by open addressing on the float's bit pattern (0 never
// occurs as a key: only values > 0 get ids). A boundary has one constant value, so the previous
// pixel's value is tried first.
class ValueIdTable {
 public:
  explicit ValueIdTable(std::vector<float>& distinct) : distinct_(distinct) { Rehash(1024); }

  int IdOf(float value) {
    const std::uint32_t key = std::bit_cast<std::uint32_t>(value);
    if (key == last_key_) return last_id_;
    std::size_t slot = Slot(key);
    while (keys_[slot] != 0 && keys_[slot] != key) slot = (slot + 1) & mask_;
    if (keys_[slot] == 0) {
      keys_[slot] = key;
      ids_[slot] = static_cast<int>(distinct_.size());
      distinct_.push_back(value);
      if (2 * distinct_.size() > keys_.size()) {
        Rehash(2 * keys_.size());
        slot = Slot(key);
        while (keys_[slot] != key) slot = (slot + 1) & mask_;
      }
    }
    last_key_ = key;
    last_id_ = ids_[slot];
    return last_id_;
  }

 private:
  std::size_t Slot(std::uint32_t key) const {
    return static_cast<std::size_t>((key * 2654435761u) >> 7) & mask_;
  }
  void Rehash(std::size_t capacity) {
    std::vector<std::uint32_t> old_keys = std::move(keys_);
    std::vector<int> old_ids = std::move(ids_);
    keys_.assign(capacity, 0);
    ids_.assign(capacity, 0);
    mask_ = capacity - 1;
    for (std::size_t i = 0; i < old_keys.size(); ++i) {
      if (old_keys[i] == 0) continue;
      std::size_t slot = Slot(old_keys[i]);
      while (keys_[slot] != 0) slot = (slot + 1) & mask_;
      keys_[slot] = old_keys[i];
      ids_[slot] = old_ids[i];
    }
  }

  std::vector<float>& distinct_;
  std::vector<std::uint32_t> keys_;
  std::vector<int> ids_;
  std::size_t mask_ = 0;
  std::uint32_t last_key_ = 0;
  int last_id_ = -1;
};

}  // namespace

Result<SparseEdgeMap> SparseEdgeMap::Build(const cv::Mat1f& region_map) {
  SparseEdgeMap out;
  out.size_ = region_map.size();
  const int rows = region_map.rows, cols = region_map.cols;
  out.bands_ = (cols + kBandWidth - 1) >> kBandShift;
  const std::size_t stride = static_cast<std::size_t>(rows) + 1;  // row offsets per band
  // Pass 1, row-major: collect the entries (row y's are [row_major_start[y], ...[y + 1])) and
  // count them per (band, row).
  std::vector<Entry> row_major;
  std::vector<int> row_major_start(rows + 1, 0);
  std::vector<int> counts(static_cast<std::size_t>(out.bands_) * stride, 0);
  ValueIdTable ids(out.distinct_values_);
  for (int y = 0; y < rows; ++y) {
    const float* row = region_map[y];
    for (int x = 0; x < cols; ++x) {
      const float value = row[x];
      if (value == 0.f) continue;  // NaN compares unequal, so it is caught below
      if (!std::isfinite(value)) {
        return Status::InvalidArgument(
            "BoxFeatureExtractor: region_map contains NaN or infinity (at row " +
            std::to_string(y) + ", column " + std::to_string(x) + ")");
      }
      row_major.push_back({x, value, value > 0.f ? ids.IdOf(value) : -1});
      ++counts[static_cast<std::size_t>(x >> kBandShift) * stride + y];
    }
    row_major_start[y + 1] = static_cast<int>(row_major.size());
  }
  // Pass 2: offsets in band-major order, then a stable scatter (rows ascending, columns
  // ascending within a row, as visited).
  out.row_start_.resize(counts.size() + 1);
  int total = 0;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    out.row_start_[i] = total;
    total += counts[i];
  }
  out.row_start_.back() = total;
  out.entries_.resize(row_major.size());
  std::vector<int>& next = counts;  // reused: next free slot of each (band, row)
  std::copy(out.row_start_.begin(), out.row_start_.end() - 1, next.begin());
  for (int y = 0; y < rows; ++y) {
    for (int i = row_major_start[y]; i < row_major_start[y + 1]; ++i) {
      const Entry& e = row_major[i];
      out.entries_[next[static_cast<std::size_t>(e.column >> kBandShift) * stride + y]++] = e;
    }
  }
  return out;
}

BoxEdgeStats SparseEdgeMap::Measure(const cv::Rect& box, const cv::Rect& inner) const {
  BoxEdgeStats stats;
  if (box.empty()) return stats;
  // Occurrences per value id; all zero between calls (only touched ids are used and reset).
  thread_local std::vector<int> counts;
  thread_local std::vector<int> touched;
  if (counts.size() < distinct_values_.size()) counts.resize(distinct_values_.size(), 0);
  touched.clear();

  const std::size_t stride = static_cast<std::size_t>(size_.height) + 1;
  const int x0 = box.x, x1 = box.x + box.width;
  const int y0 = box.y, y1 = box.y + box.height;
  // An empty sub-box gets an empty column range, so no entry is ever inside it.
  const int ix0 = inner.empty() ? 0 : inner.x, ix1 = inner.empty() ? 0 : inner.x + inner.width;
  const int iy0 = inner.y, iy1 = inner.y + inner.height;
  // Local accumulators: counts[] is an int array, so the compiler could not keep stats.count in
  // a register (possible aliasing).
  double sum = 0.0, inner_sum = 0.0;
  int count = 0, inner_count = 0;
  int run_id = -1, run_length = 0;
  auto flush_run = [&] {
    if (run_length == 0) return;
    if (counts[run_id] == 0) touched.push_back(run_id);
    counts[run_id] += run_length;
    run_length = 0;
  };
  for (int band = x0 >> kBandShift; band <= (x1 - 1) >> kBandShift; ++band) {
    const int band_x0 = band << kBandShift, band_x1 = band_x0 + kBandWidth;
    const bool whole_band = x0 <= band_x0 && x1 >= band_x1;
    const bool touches_inner = ix0 < band_x1 && ix1 > band_x0;
    const int* row_start = row_start_.data() + band * stride;
    for (int y = y0; y < y1; ++y) {
      const bool inner_row = touches_inner && y >= iy0 && y < iy1;
      const int end = row_start[y + 1];
      for (int e = row_start[y]; e < end; ++e) {
        const Entry& entry = entries_[e];
        if (!whole_band) {
          if (entry.column < x0) continue;
          if (entry.column >= x1) break;  // columns ascend within a row
        }
        const bool positive = entry.id >= 0;
        sum += entry.value;
        count += positive;
        if (inner_row && entry.column >= ix0 && entry.column < ix1) {
          inner_sum += entry.value;
          inner_count += positive;
        }
        // Runs of one value (a boundary segment along the row) are counted in a register and
        // added at once: incrementing counts[id] per pixel serialises on the memory round trip.
        if (positive) {
          if (entry.id == run_id) {
            ++run_length;
          } else {
            flush_run();
            run_id = entry.id;
            run_length = 1;
          }
        }
      }
    }
  }
  flush_run();
  stats.sum = sum;
  stats.count = count;
  stats.inner_sum = inner_sum;
  stats.inner_count = inner_count;
  if (touched.empty()) return stats;
  int mode_id = touched.front();
  float max_value = distinct_values_[mode_id];
  for (const int id : touched) {
    const float value = distinct_values_[id];
    max_value = std::max(max_value, value);
    if (counts[id] > counts[mode_id] ||
        (counts[id] == counts[mode_id] && value < distinct_values_[mode_id])) {
      mode_id = id;
    }
  }
  stats.max_value = max_value;
  stats.mode_value = distinct_values_[mode_id];
  stats.mode_count = counts[mode_id];
  for (const int id : touched) counts[id] = 0;
  return stats;
}

}  // namespace tod
