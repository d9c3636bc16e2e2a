#include "core/edges/superpixel_boundaries.h"

#include <algorithm>
#include <vector>

namespace tod {

int RelabelConnectedComponents(cv::Mat1i& labels) {
  const int width = labels.cols;
  const int height = labels.rows;
  const size_t n = static_cast<size_t>(width) * height;
  if (n == 0) return 0;
  if (!labels.isContinuous()) labels = labels.clone();
  int* const l = labels.ptr<int>(0);
  std::vector<int> out(n, 0);
  std::vector<int> stack;
  int count = 0;
  for (size_t seed = 0; seed < n; ++seed) {
    if (out[seed] != 0) continue;
    const int id = l[seed];
    out[seed] = ++count;
    stack.push_back(static_cast<int>(seed));
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const int x = i % width;
      const int y = i / width;
      auto visit = [&](int j) {
        if (out[j] == 0 && l[j] == id) {
          out[j] = count;
          stack.push_back(j);
        }
      };
      if (x > 0) visit(i - 1);
      if (x + 1 < width) visit(i + 1);
      if (y > 0) visit(i - width);
      if (y + 1 < height) visit(i + width);
    }
  }
  std::copy(out.begin(), out.end(), l);
  return count;
}

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
  // Missing neighbours (outside the image) take no part, as in the pairwise definitions.

  // Step 1: the stronger-edge pixel of every differing 4-adjacent pair (ties: the first pixel).
  // Pixel i is marked by the pair it forms with its left or upper neighbour j when
  // !(e[j] >= e[i]), and by the pair with its right or lower neighbour j when e[i] >= e[j].
  std::vector<int> step1(n);
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(y) * width;
    const int* const lr = l + row;
    const float* const er = e + row;
    // Rows outside the image are replaced by the row itself: a pixel never differs from itself.
    const int* const lu = y > 0 ? lr - width : lr;
    const float* const eu = y > 0 ? er - width : er;
    const int* const ld = y + 1 < height ? lr + width : lr;
    const float* const ed = y + 1 < height ? er + width : er;
    int* const out = step1.data() + row;
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

  // Step 2: separate diagonal contacts, judged on the step-1 map (a snapshot, so the raster order
  // does not matter). Outside the image counts as the pixel's own label: a labelled pixel is
  // marked when some 8-neighbour carries another non-zero label and some 4-neighbour differs
  // from its own.
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(y) * width;
    const int* const sr = step1.data() + row;
    const int* const su = y > 0 ? sr - width : sr;  // outside: the row itself, as above
    const int* const sd = y + 1 < height ? sr + width : sr;
    int* const out = l + row;
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

  // Step 3: thinning, in place so that two halves of a thick boundary cannot both be returned to
  // their different sides. Whether the labelled 8-neighbours share one label does not depend on
  // the order they are looked at, so pixels away from the image border take a path without
  // bounds checks.
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
