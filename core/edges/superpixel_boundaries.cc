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

  // Step 1: the stronger-edge pixel of every differing 4-adjacent pair (ties: the first pixel).
  std::vector<unsigned char> mark(n, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      auto pair = [&](size_t j) {
        if (l[i] != l[j]) mark[e[i] >= e[j] ? i : j] = 1;
      };
      if (x + 1 < width) pair(i + 1);
      if (y + 1 < height) pair(i + width);
    }
  }
  for (size_t i = 0; i < n; ++i)
    if (mark[i]) l[i] = 0;

  // Step 2: separate diagonal contacts, judged on the step-1 map (a snapshot, so the raster order
  // does not matter). Outside the image counts as the pixel's own label.
  std::fill(mark.begin(), mark.end(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      const int own = l[i];
      if (own == 0) continue;
      bool touches_other = false;
      for (int dy = -1; dy <= 1 && !touches_other; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          const int yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= width || yy >= height) continue;
          const int t = l[static_cast<size_t>(yy) * width + xx];
          if (t != 0 && t != own) {
            touches_other = true;
            break;
          }
        }
      }
      if (!touches_other) continue;
      const bool enclosed = (x == 0 || l[i - 1] == own) && (x + 1 == width || l[i + 1] == own) &&
                            (y == 0 || l[i - width] == own) &&
                            (y + 1 == height || l[i + width] == own);
      if (!enclosed) mark[i] = 1;
    }
  }
  for (size_t i = 0; i < n; ++i)
    if (mark[i]) l[i] = 0;

  // Step 3: thinning, in place so that two halves of a thick boundary cannot both be returned to
  // their different sides.
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = static_cast<size_t>(y) * width + x;
      if (l[i] != 0) continue;
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
