// ClearCropBorderEdges (ALGORITHM.md §3.2(4)).
#include <vector>

#include "core/proposals/edge_box_scorer.h"

namespace tod {
namespace {

// Reads the original map with zeros outside it.
float At(const cv::Mat1f& m, int r, int c) {
  return (r >= 0 && c >= 0 && r < m.rows && c < m.cols) ? m(r, c) : 0.f;
}

}  // namespace

void ClearCropBorderEdges(cv::Mat1f& region_map) {
  if (region_map.empty()) return;
  const cv::Mat1f original = region_map.clone();  // decisions use the unmodified map
  const int h = original.rows, w = original.cols;
  std::vector<cv::Point> cleared;
  // A border pixel goes when it merely runs along the border: its inward neighbour is zero
  // (a 1-pixel frame line), or the inward neighbour, the next pixel along the border and that
  // pixel's inward neighbour are all non-zero (a 2-pixel frame line). A contour that meets the
  // border perpendicularly has a non-zero inward neighbour but no border continuation.
  const auto check = [&](int r, int c, int in_dr, int in_dc, int along_dr, int along_dc) {
    if (original(r, c) == 0.f) return;
    const bool inward = At(original, r + in_dr, c + in_dc) != 0.f;
    const bool along = At(original, r + along_dr, c + along_dc) != 0.f &&
                       At(original, r + along_dr + in_dr, c + along_dc + in_dc) != 0.f;
    if (!inward || along) cleared.emplace_back(c, r);
  };
  for (int r = 0; r < h; ++r) {
    check(r, 0, 0, 1, 1, 0);       // left column, inward = right
    check(r, w - 1, 0, -1, 1, 0);  // right column, inward = left
  }
  for (int c = 0; c < w; ++c) {
    check(0, c, 1, 0, 0, 1);       // top row, inward = down
    check(h - 1, c, -1, 0, 0, 1);  // bottom row, inward = up
  }
  for (const cv::Point& p : cleared) region_map(p.y, p.x) = 0.f;
}

}  // namespace tod
