#include "core/edges/superpixel_boundaries.h"

#include <algorithm>
#include <opencv2/core/utility.hpp>
#include <vector>

namespace tod {

namespace {

// A maximal horizontal stretch of one label in one row.
struct Run {
  int start;  // first column
  int end;    // one past the last column
  int label;
};

// The runs of a row-major label map in raster order; row_first[y] is the index of row y's first
// run (row_first[height] = the number of runs).
struct RunsOfRows {
  std::vector<Run> runs;
  std::vector<size_t> row_first;
};

RunsOfRows CollectRuns(const int* l, int width, int height) {
  RunsOfRows out;
  out.row_first.resize(static_cast<size_t>(height) + 1);
  for (int y = 0; y < height; ++y) {
    out.row_first[y] = out.runs.size();
    const int* const row = l + static_cast<size_t>(y) * width;
    for (int x = 0; x < width;) {
      const int start = x;
      const int label = row[x];
      while (++x < width && row[x] == label) {
      }
      out.runs.push_back({start, x, label});
    }
  }
  out.row_first[height] = out.runs.size();
  return out;
}

// Union-find over runs; the root of a set is its earliest run.
class RunSets {
 public:
  explicit RunSets(size_t count) : parent_(count) {
    for (size_t r = 0; r < count; ++r) parent_[r] = r;
  }
  size_t Find(size_t r) {
    while (parent_[r] != r) {
      parent_[r] = parent_[parent_[r]];  // path halving
      r = parent_[r];
    }
    return r;
  }
  void Unite(size_t a, size_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<size_t> parent_;
};

// A run 4-touches a run of the row above exactly when their column ranges overlap, so a merge
// walk over each pair of rows unites every such pair with the same label.
void UniteTouchingRuns(const RunsOfRows& rows, int height, RunSets& sets) {
  const std::vector<Run>& runs = rows.runs;
  for (int y = 1; y < height; ++y) {
    size_t up = rows.row_first[y - 1];
    size_t down = rows.row_first[y];
    const size_t up_end = rows.row_first[y];
    const size_t down_end = rows.row_first[y + 1];
    // Invariant: runs `up` and `down` overlap (both rows start at column 0; the run that ends
    // first is replaced by its successor, which starts where it ended, inside the other run).
    while (up < up_end && down < down_end) {
      if (runs[up].label == runs[down].label) sets.Unite(up, down);
      const int up_stop = runs[up].end;
      const int down_stop = runs[down].end;
      if (up_stop <= down_stop) ++up;
      if (down_stop <= up_stop) ++down;
    }
  }
}

}  // namespace

int RelabelConnectedComponents(cv::Mat1i& labels) {
  const int width = labels.cols;
  const int height = labels.rows;
  if (static_cast<size_t>(width) * height == 0) return 0;
  if (!labels.isContinuous()) labels = labels.clone();
  int* const l = labels.ptr<int>(0);

  // Two passes over runs instead of a per-pixel flood fill: a superpixel row is a few long runs,
  // so the work is per run, with no stack, no division to recover coordinates and no
  // unpredictable branch per pixel.
  //  1. Runs, row by row in raster order, united with the touching runs of the row above.
  //  2. Ids in raster order of the runs: a component's first run holds its first pixel in raster
  //     order, so components are numbered in order of first appearance, which is exactly how the
  //     flood fill, seeding in raster order, numbered them.
  const RunsOfRows rows = CollectRuns(l, width, height);
  RunSets sets(rows.runs.size());
  UniteTouchingRuns(rows, height, sets);

  std::vector<int> id(rows.runs.size(), 0);
  int count = 0;
  for (size_t r = 0; r < rows.runs.size(); ++r) {
    int& component = id[sets.Find(r)];
    if (component == 0) component = ++count;
    id[r] = component;
  }
  for (int y = 0; y < height; ++y) {
    int* const row = l + static_cast<size_t>(y) * width;
    for (size_t r = rows.row_first[y]; r < rows.row_first[y + 1]; ++r) {
      std::fill(row + rows.runs[r].start, row + rows.runs[r].end, id[r]);
    }
  }
  return count;
}

namespace {

// Step 1 of InsertSuperpixelBoundaries on row y: `out` (the row of the step-1 map) gets 0 where
// the pixel is the stronger-edge pixel of a differing 4-adjacent pair (ties: the first pixel),
// else its label. Pixel i is marked by the pair it forms with its left or upper neighbour j when
// !(e[j] >= e[i]), and by the pair with its right or lower neighbour j when e[i] >= e[j]. (A
// function of plain values: inside a lambda, the row loop read the width through a reference that
// the stores to `out` might alias, and did not vectorise.)
void MarkStrongerEdgeRow(const int* l, const float* e, int width, int height, int y, int* out) {
  const size_t row = static_cast<size_t>(y) * width;
  const int* const lr = l + row;
  const float* const er = e + row;
  // Rows outside the image are replaced by the row itself: a pixel never differs from itself.
  const int* const lu = y > 0 ? lr - width : lr;
  const float* const eu = y > 0 ? er - width : er;
  const int* const ld = y + 1 < height ? lr + width : lr;
  const float* const ed = y + 1 < height ? er + width : er;
  const auto pixel = [&](int x, bool has_left, bool has_right) {
    const int own = lr[x];
    const float ei = er[x];
    bool marked = ((lu[x] != own) & !(eu[x] >= ei)) | ((ld[x] != own) & (ei >= ed[x]));
    if (has_left) marked |= (lr[x - 1] != own) & !(er[x - 1] >= ei);
    if (has_right) marked |= (lr[x + 1] != own) & (ei >= er[x + 1]);
    out[x] = marked ? 0 : own;
  };
  pixel(0, false, width > 1);
  for (int x = 1; x + 1 < width; ++x) pixel(x, true, true);
  if (width > 1) pixel(width - 1, true, false);
}

// Step 2 on row y of the step-1 map `marks`: a labelled pixel is marked (0 in `out`) when some
// 8-neighbour carries another non-zero label and some 4-neighbour differs from its own. Outside
// the image counts as the pixel's own label.
void SeparateDiagonalRow(const int* marks, int width, int height, int y, int* out) {
  const size_t row = static_cast<size_t>(y) * width;
  const int* const sr = marks + row;
  const int* const su = y > 0 ? sr - width : sr;  // outside: the row itself, as above
  const int* const sd = y + 1 < height ? sr + width : sr;
  const auto pixel = [&](int x, bool has_left, bool has_right) {
    const int own = sr[x];
    const auto other = [own](int t) { return (t != 0) & (t != own); };
    bool open = (su[x] != own) | (sd[x] != own);  // a 4-neighbour differs from own
    bool touches = other(su[x]) | other(sd[x]);   // an 8-neighbour: another non-zero label
    if (has_left) {
      open |= sr[x - 1] != own;
      touches |= other(sr[x - 1]) | other(su[x - 1]) | other(sd[x - 1]);
    }
    if (has_right) {
      open |= sr[x + 1] != own;
      touches |= other(sr[x + 1]) | other(su[x + 1]) | other(sd[x + 1]);
    }
    out[x] = (open & touches) ? 0 : own;  // own == 0 stays 0 either way
  };
  pixel(0, false, width > 1);
  for (int x = 1; x + 1 < width; ++x) pixel(x, true, true);
  if (width > 1) pixel(width - 1, true, false);
}

// Step 3 of InsertSuperpixelBoundaries: a boundary pixel (0) whose labelled 8-neighbours all
// share one label goes back to that label. In place, in raster order, so that two halves of a
// thick boundary cannot both be returned to their different sides. Whether the labelled
// 8-neighbours share one label does not depend on the order they are looked at, so pixels away
// from the image border take a path without bounds checks.
void ThinBoundaries(int* l, int width, int height) {
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      if (l[i] != 0) continue;
      if (x > 0 && y > 0 && x + 1 < width && y + 1 < height) {
        const int* up = l + i - width;
        const int* mid = l + i;
        const int* down = l + i + width;
        const int nb[8] = {up[-1], up[0], up[1], mid[-1], mid[1], down[-1], down[0], down[1]};
        int shared = 0;
        for (const int t : nb) shared = shared != 0 ? shared : t;  // the first labelled one
        bool single = true;
        for (const int t : nb) single &= t == 0 || t == shared;
        if (single && shared != 0) l[i] = shared;
        continue;
      }
      int shared = 0;
      bool single = true;
      for (int dy = -1; dy <= 1 && single; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          const int yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= width || yy >= height) continue;
          const int t = l[static_cast<size_t>(yy) * width + xx];
          if (t == 0) continue;
          if (shared == 0) {
            shared = t;
          } else if (t != shared) {
            single = false;
            break;
          }
        }
      }
      if (single && shared != 0) l[i] = shared;
    }
  }
}

}  // namespace

void InsertSuperpixelBoundaries(const cv::Mat1f& edge, cv::Mat1i& labels) {
  const int width = labels.cols;
  const int height = labels.rows;
  const size_t n = static_cast<size_t>(width) * height;
  if (n == 0) return;
  if (!labels.isContinuous()) labels = labels.clone();
  int* const l = labels.ptr<int>(0);
  const cv::Mat1f edge_c = edge.isContinuous() ? edge : edge.clone();
  const float* const e = edge_c.ptr<float>(0);

  // Steps 1 and 2 are written per pixel, as "is this pixel marked?" computed from its
  // neighbourhood in the previous map, into a second map: no branch on the labels (whether two
  // labels differ is unpredictable along the many short borders), no read-modify-write of marks.
  // Missing neighbours (outside the image) take no part, as in the pairwise definitions. Each
  // step is a pure function of a snapshot, row by row, so its rows run on OpenCV's pool.
  std::vector<int> step1(n);
  int* const marks = step1.data();
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      MarkStrongerEdgeRow(l, e, width, height, y, marks + static_cast<size_t>(y) * width);
  });
  // Step 2: separate diagonal contacts, judged on the step-1 map (a snapshot, so the raster order
  // does not matter).
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y)
      SeparateDiagonalRow(marks, width, height, y, l + static_cast<size_t>(y) * width);
  });

  // Step 3: thinning.
  ThinBoundaries(l, width, height);
}

int CompactLabels(cv::Mat1i& labels) {
  int max_label = 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* row = labels[y];
    for (int x = 0; x < labels.cols; ++x) max_label = std::max(max_label, row[x]);
  }
  std::vector<int> remap(static_cast<size_t>(max_label) + 1, 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* row = labels[y];
    for (int x = 0; x < labels.cols; ++x) remap[row[x]] = 1;
  }
  remap[0] = 0;
  int count = 0;
  for (int id = 1; id <= max_label; ++id)
    if (remap[id]) remap[id] = ++count;
  for (int y = 0; y < labels.rows; ++y) {
    int* row = labels[y];
    for (int x = 0; x < labels.cols; ++x) row[x] = remap[row[x]];
  }
  return count;
}

}  // namespace tod
