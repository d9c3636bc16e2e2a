// Colour data for features 15-20 (ALGORITHM.md §5) of one colour crop, built once and shared by
// every region cut from it (the multilayer regions are nested crops of R1, so one frame needs one
// ColourIntegrals; only the edge map differs between regions).
//
// Memory is the cost that matters (first-touch page faults dominate): instead of 48 full-resolution
// histogram integrals (192 B/pixel) and 6 double moment integrals (48 B/pixel), this keeps
//  * per pixel: an 8-byte code (the three histogram bins and the integers H, S, V derive from),
//    stored twice, row-major and column-major, so that every strip below is read sequentially
//    (a column strip read row-major costs one cache miss per row);
//  * per corner of a coarse cell grid (kColourCellSize): the 48 bin counts as uint16 with
//    wrap-around arithmetic (exact for any rectangle holding fewer than 65536 pixels; larger
//    rectangles are split into tiles) and the 6 moments (sum and sum of squares of H, S, V) as
//    double.
// A rectangle's histogram / moments = grid lookup for its largest cell-aligned inner rectangle +
// a scan of the (less than one cell wide) strips around it. Both are exact.
//
// The grid lines lie at full-image multiples of kColourCellSize (plus the crop's own borders), so
// crops of the same image share grid lines: snapping a rectangle (SnapToGrid) then gives the same
// pixels whichever crop the integrals were built from.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/features/hsv.h"

namespace tod {

inline constexpr int kColourCellSize = 4;

// 48 bin counts in the layout of hsv.h: 16 H bins, then 16 S, then 16 V.
using ColourHistogram = std::array<int, kColourHistBins>;
// Sums over a rectangle: H, S, V, then H^2, S^2, V^2.
using ColourMoments = std::array<double, 6>;

class ColourIntegrals {
 public:
  // bgr: the colour crop; crop_origin: its top-left corner in the full image (aligns the grid).
  ColourIntegrals(const cv::Mat3b& bgr, cv::Point crop_origin);

  cv::Size size() const { return size_; }
  cv::Point origin() const { return origin_; }

  // Exact 48-bin histogram of a crop-local rectangle, which must lie inside the crop.
  ColourHistogram Histogram(const cv::Rect& rect) const;
  // Exact (up to double rounding) sums of H, S, V and their squares over a crop-local rectangle.
  ColourMoments Moments(const cv::Rect& rect) const;
  // rect with each side moved to the nearest grid line (full-image multiple of kColourCellSize,
  // ties away from the top-left), then clamped to `bounds`. Monotone, so containment is kept.
  cv::Rect SnapToGrid(const cv::Rect& rect, const cv::Rect& bounds) const;

 private:
  // Grid lines along one axis: positions (crop-local, ascending, first 0, last = extent) and,
  // for every coordinate 0..extent, the index of the first line at or after it and of the last
  // line at or before it.
  struct Axis {
    std::vector<int> lines;
    std::vector<int> ceil_line;
    std::vector<int> floor_line;
    int origin = 0;  // full-image coordinate of crop position 0
  };
  static Axis MakeAxis(int extent, int origin);
  static int SnapCoordinate(const Axis& axis, int local);

  // A rectangle = its largest cell-aligned inner rectangle (line indices; absent when the
  // rectangle is narrower than a cell) + up to four strips around it, each less than a cell wide.
  struct Split {
    bool has_inner = false;
    int lx0 = 0, lx1 = 0, ly0 = 0, ly1 = 0;
    std::array<cv::Rect, 4> strips;  // top, bottom, left, right; may be empty
  };
  Split Decompose(const cv::Rect& rect) const;

  const std::uint16_t* HistCorner(int line_y, int line_x) const;
  const double* MomentCorner(int line_y, int line_x) const;
  void AddAlignedHistogram(int ly0, int ly1, int lx0, int lx1, ColourHistogram& hist) const;
  // Calls visit(codes, n) for every row (rect at least as wide as high) or column (otherwise) of
  // rect, top to bottom / left to right: the layout in which that line is contiguous.
  template <typename Visit>
  void ForEachSpan(const cv::Rect& rect, Visit&& visit) const;

  void BuildPixels(const cv::Mat3b& bgr);
  void BuildCorners();

  cv::Size size_;
  cv::Point origin_;
  Axis x_axis_, y_axis_;
  struct PixelCode {
    std::array<std::uint8_t, 3> bins;  // offset into the 48-bin layout: H, 16 + S, 32 + V
    std::uint8_t max_level;            // the arguments of HsvFromLevels
    std::uint8_t delta;
    std::uint8_t unused;
    std::uint16_t hue_units;
  };
  static_assert(sizeof(PixelCode) == 8);
  std::unique_ptr<PixelCode[]> row_major_;     // y * width + x
  std::unique_ptr<PixelCode[]> column_major_;  // x * height + y
  // Per grid corner (line_y * num x lines + line_x): 48 counts / 6 moments of [0, x) x [0, y).
  std::unique_ptr<std::uint16_t[]> hist_corners_;
  std::unique_ptr<double[]> moment_corners_;
};

}  // namespace tod
