#include "core/features/sparse_edge_map.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace tod {
namespace {

// Distinct non-zero values -> dense ids, by open addressing on the float's bit pattern (0 never
// occurs as a key: +0 is skipped, -0 compares equal to it and is skipped too). A boundary has one
// constant value, so the previous run's value is tried first.
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
  out.index_stride_ = (cols >> kIndexShift) + 1;
  out.row_start_.assign(static_cast<std::size_t>(rows) + 1, 0);
  out.first_run_.resize(static_cast<std::size_t>(rows) * out.index_stride_);
  std::vector<std::int64_t> pixels_of_id;  // for the exactness bound of the sums
  ValueIdTable ids(out.values_);
  for (int y = 0; y < rows; ++y) {
    const float* row = region_map[y];
    const int row_begin = static_cast<int>(out.runs_.size());
    for (int x = 0; x < cols;) {
      const float value = row[x];
      if (value == 0.f) {  // NaN compares unequal, so it is caught below
        ++x;
        continue;
      }
      if (!std::isfinite(value)) {
        return Status::InvalidArgument(
            "BoxFeatureExtractor: region_map contains NaN or infinity (at row " +
            std::to_string(y) + ", column " + std::to_string(x) + ")");
      }
      // The run ends at the first pixel with another bit pattern (a NaN there stops it and is
      // reported when the scan reaches it, as before).
      const std::uint32_t key = std::bit_cast<std::uint32_t>(value);
      int end = x + 1;
      while (end < cols && std::bit_cast<std::uint32_t>(row[end]) == key) ++end;
      const int id = ids.IdOf(value);
      if (id == static_cast<int>(pixels_of_id.size())) pixels_of_id.push_back(0);
      pixels_of_id[id] += end - x;
      out.runs_.push_back({x, end, id});
      x = end;
    }
    const int row_end = static_cast<int>(out.runs_.size());
    out.row_start_[y + 1] = row_end;
    int* index = out.first_run_.data() + static_cast<std::size_t>(y) * out.index_stride_;
    for (int block = 0, r = row_begin; block < out.index_stride_; ++block) {
      while (r < row_end && out.runs_[r].end <= (block << kIndexShift)) ++r;
      index[block] = r;
    }
  }

  out.DecideExactSums(pixels_of_id);
  return out;
}

void SparseEdgeMap::DecideExactSums(const std::vector<std::int64_t>& pixels_of_id) {
  // Exactness of the sums (see the header). q = the smallest ulp among the values (a float of
  // exponent e is a multiple of 2^(e - 23); subnormals of 2^-149); every value is then an integer
  // number of q's, and if the map's total |M| is at most 2^53 q, no double partial sum of any
  // subset in any order can round.
  constexpr std::int64_t kExactLimit = std::int64_t{1} << std::numeric_limits<double>::digits;
  constexpr int kFloatFraction = std::numeric_limits<float>::digits - 1;  // 23
  constexpr int kMinQuantumExponent =
      std::numeric_limits<float>::min_exponent - std::numeric_limits<float>::digits;  // -149
  int quantum_exponent = std::numeric_limits<int>::max();
  for (const float value : values_) {
    quantum_exponent = std::min(quantum_exponent,
                                std::max(std::ilogb(value) - kFloatFraction, kMinQuantumExponent));
  }
  sums_exact_ = true;
  units_.resize(values_.size());
  std::int64_t total_units = 0;  // sum of |M| / q over the map, checked against kExactLimit
  for (std::size_t id = 0; id < values_.size() && sums_exact_; ++id) {
    const double units = std::ldexp(static_cast<double>(values_[id]), -quantum_exponent);
    const double magnitude = std::abs(units);
    if (magnitude > static_cast<double>(kExactLimit) ||
        static_cast<std::int64_t>(magnitude) > (kExactLimit - total_units) / pixels_of_id[id]) {
      sums_exact_ = false;
      break;
    }
    units_[id] = static_cast<std::int64_t>(units);  // an integer: no rounding
    total_units += static_cast<std::int64_t>(magnitude) * pixels_of_id[id];
  }
  if (!sums_exact_) {
    units_.clear();
  } else if (!values_.empty()) {
    quantum_ = std::ldexp(1.0, quantum_exponent);
  }
}

int SparseEdgeMap::FirstRunAfter(int y, int x) const {
  int r = first_run_[static_cast<std::size_t>(y) * index_stride_ + (x >> kIndexShift)];
  const int end = row_start_[y + 1];
  while (r < end && runs_[r].end <= x) ++r;  // at most the runs of one 16-column block
  return r;
}

BoxEdgeStats SparseEdgeMap::Measure(const cv::Rect& box, const cv::Rect& inner) const {
  if (box.empty()) return {};
  // Pixels per value id in the box and in the centre sub-box; all zero between calls (only the
  // touched ids are read and reset). touched has room for every id plus one scratch slot.
  thread_local std::vector<Tally> tallies;
  thread_local std::vector<int> touched;
  if (tallies.size() < values_.size()) tallies.resize(values_.size(), Tally{0, 0});
  if (touched.size() < values_.size() + 1) touched.resize(values_.size() + 1);
  const int num_touched = TallyRuns(box, inner, tallies.data(), touched.data());
  return StatsFromTallies(box, inner, tallies.data(), touched.data(), num_touched);
}

int SparseEdgeMap::TallyRuns(const cv::Rect& box, const cv::Rect& inner, Tally* const tally,
                             int* const touched_ids) const {
  // Raw pointers in locals: the stores into the tallies could otherwise alias the members and
  // force reloads in the inner loop.
  const Run* const runs = runs_.data();
  const int* const row_start = row_start_.data();
  const int* const first_run = first_run_.data();
  const std::size_t stride = static_cast<std::size_t>(index_stride_);

  const int x0 = box.x, x1 = box.x + box.width;
  const int y0 = box.y, y1 = box.y + box.height;
  // Rows outside the centre sub-box get an empty column range [0, 0): every run then has a
  // non-positive inner length, clamped to 0 (runs start at column >= 0).
  const bool has_inner = !inner.empty();
  const int ix0 = has_inner ? inner.x : 0, ix1 = has_inner ? inner.x + inner.width : 0;
  const int iy0 = has_inner ? inner.y : 0, iy1 = has_inner ? inner.y + inner.height : 0;
  int num_touched = 0;
  for (int y = y0; y < y1; ++y) {
    const bool inner_row = y >= iy0 && y < iy1;
    const int cx0 = inner_row ? ix0 : 0, cx1 = inner_row ? ix1 : 0;
    const int end = row_start[y + 1];
    int r = first_run[static_cast<std::size_t>(y) * stride + (x0 >> kIndexShift)];
    while (r < end && runs[r].end <= x0) ++r;     // at most the runs of one index block
    for (; r < end && runs[r].begin < x1; ++r) {  // runs ascend within a row
      const Run run = runs[r];
      Tally& t = tally[run.id];
      // Branch-free "first time seen": always write, advance only for a new id.
      touched_ids[num_touched] = run.id;
      num_touched += t.box == 0;
      t.box += std::min(run.end, x1) - std::max(run.begin, x0);
      t.inner += std::max(0, std::min(run.end, cx1) - std::max(run.begin, cx0));
    }
  }
  return num_touched;
}

BoxEdgeStats SparseEdgeMap::StatsFromTallies(const cv::Rect& box, const cv::Rect& inner,
                                             Tally* const tally, const int* const touched_ids,
                                             int num_touched) const {
  // Values are distinct, so (count descending, value ascending) is a strict order and the mode
  // does not depend on the order of the ids.
  const bool exact = sums_exact_;
  std::int64_t units = 0, inner_units = 0;
  int count = 0, inner_count = 0, mode_count = 0;
  float mode_value = 0.f, max_value = 0.f;
  for (int i = 0; i < num_touched; ++i) {
    const int id = touched_ids[i];
    const Tally t = tally[id];
    tally[id] = Tally{0, 0};
    if (exact) {
      units += t.box * units_[id];
      inner_units += t.inner * units_[id];
    }
    const float value = values_[id];
    if (value <= 0.f) continue;  // negative values count in the sums only
    count += t.box;
    inner_count += t.inner;
    max_value = std::max(max_value, value);
    if (t.box > mode_count || (t.box == mode_count && value < mode_value)) {
      mode_count = t.box;
      mode_value = value;
    }
  }
  BoxEdgeStats stats;
  stats.max_value = max_value;
  stats.mode_value = mode_value;
  stats.mode_count = mode_count;
  stats.count = count;
  stats.inner_count = inner_count;
  if (exact) {
    stats.sum = static_cast<double>(units) * quantum_;  // |units| <= 2^53: exact, as is * 2^k
    stats.inner_sum = static_cast<double>(inner_units) * quantum_;
  } else {
    SequentialSums(box, inner, stats);
  }
  return stats;
}

void SparseEdgeMap::SequentialSums(const cv::Rect& box, const cv::Rect& inner,
                                   BoxEdgeStats& stats) const {
  // The original order: 64-column bands left to right, rows top to bottom, columns ascending,
  // one double addition per pixel.
  const int x0 = box.x, x1 = box.x + box.width;
  const int y0 = box.y, y1 = box.y + box.height;
  const bool has_inner = !inner.empty();
  const int ix0 = has_inner ? inner.x : 0, ix1 = has_inner ? inner.x + inner.width : 0;
  const int iy0 = has_inner ? inner.y : 0, iy1 = has_inner ? inner.y + inner.height : 0;
  double sum = 0.0, inner_sum = 0.0;
  for (int band = x0 >> kBandShift; band <= (x1 - 1) >> kBandShift; ++band) {
    const int bx0 = std::max(x0, band << kBandShift);
    const int bx1 = std::min(x1, (band + 1) << kBandShift);
    for (int y = y0; y < y1; ++y) {
      const bool inner_row = y >= iy0 && y < iy1;
      const int end = row_start_[y + 1];
      for (int r = FirstRunAfter(y, bx0); r < end && runs_[r].begin < bx1; ++r) {
        const float value = values_[runs_[r].id];
        const int c1 = std::min(runs_[r].end, bx1);
        for (int c = std::max(runs_[r].begin, bx0); c < c1; ++c) {
          sum += value;
          if (inner_row && c >= ix0 && c < ix1) inner_sum += value;
        }
      }
    }
  }
  stats.sum = sum;
  stats.inner_sum = inner_sum;
}

}  // namespace tod
