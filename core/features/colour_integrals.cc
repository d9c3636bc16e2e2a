#include "core/features/colour_integrals.h"

#include <algorithm>
#include <opencv2/core/utility.hpp>

namespace tod {
namespace {

// Largest number of grid cells whose pixels (at most kColourCellSize^2 each) stay below 65536,
// the limit of exact uint16 wrap-around sums.
constexpr int kMaxCellsPerTile = 65535 / (kColourCellSize * kColourCellSize);

int FloorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

ColourIntegrals::Axis ColourIntegrals::MakeAxis(int extent, int origin) {
  Axis axis;
  axis.origin = origin;
  axis.lines.push_back(0);
  for (int local = 1; local < extent; ++local) {
    if ((origin + local) % kColourCellSize == 0) axis.lines.push_back(local);
  }
  if (extent > 0) axis.lines.push_back(extent);
  axis.ceil_line.resize(extent + 1);
  axis.floor_line.resize(extent + 1);
  int next = 0;  // first line at or after `local`
  for (int local = 0; local <= extent; ++local) {
    while (axis.lines[next] < local) ++next;
    axis.ceil_line[local] = next;
    axis.floor_line[local] = axis.lines[next] == local ? next : next - 1;
  }
  return axis;
}

ColourIntegrals::ColourIntegrals(const cv::Mat3b& bgr, cv::Point crop_origin)
    : size_(bgr.size()),
      origin_(crop_origin),
      x_axis_(MakeAxis(bgr.cols, crop_origin.x)),
      y_axis_(MakeAxis(bgr.rows, crop_origin.y)) {
  BuildPixels(bgr);
  BuildCorners();
}

void ColourIntegrals::BuildPixels(const cv::Mat3b& bgr) {
  const int width = size_.width, height = size_.height;
  const std::size_t pixels = static_cast<std::size_t>(size_.area());
  // Every entry is written below: no zero-filling of the (large) per-pixel tables.
  row_major_ = std::make_unique_for_overwrite<PixelCode[]>(pixels);
  column_major_ = std::make_unique_for_overwrite<PixelCode[]>(pixels);
  // Rows (and tile rows of the transpose) are independent: they run on OpenCV's pool, as wide as
  // the request's threads (cv::setNumThreads), with the same result for any width.
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const cv::Vec3b* row = bgr[y];
      PixelCode* code = row_major_.get() + static_cast<std::size_t>(y) * width;
      for (int x = 0; x < width; ++x, ++code) {
        const PixelColour c = ClassifyPixel(row[x][0], row[x][1], row[x][2]);
        code->bins = {c.hue_bin, static_cast<std::uint8_t>(kHueBins + c.sat_bin),
                      static_cast<std::uint8_t>(kHueBins + kSatValBins + c.val_bin)};
        code->max_level = c.max_level;
        code->delta = c.delta;
        code->unused = 0;
        code->hue_units = c.hue_units;
      }
    }
  });
  // Transpose in tiles so that both sides stay in cache.
  constexpr int kTile = 32;
  const int tile_rows = (height + kTile - 1) / kTile;
  cv::parallel_for_(cv::Range(0, tile_rows), [&](const cv::Range& bands) {
    for (int ty = bands.start * kTile; ty < std::min(height, bands.end * kTile); ty += kTile) {
      for (int tx = 0; tx < width; tx += kTile) {
        for (int x = tx; x < std::min(width, tx + kTile); ++x) {
          for (int y = ty; y < std::min(height, ty + kTile); ++y) {
            column_major_[static_cast<std::size_t>(x) * height + y] =
                row_major_[static_cast<std::size_t>(y) * width + x];
          }
        }
      }
    }
  });
}

void ColourIntegrals::BuildCorners() {
  const int lines_x = static_cast<int>(x_axis_.lines.size());
  const int lines_y = static_cast<int>(y_axis_.lines.size());
  const int cells_x = lines_x - 1;
  const std::size_t corners = static_cast<std::size_t>(lines_x) * lines_y;
  hist_corners_ = std::make_unique<std::uint16_t[]>(corners * kColourHistBins);
  moment_corners_ = std::make_unique<double[]>(corners * 6);
  if (cells_x <= 0) return;
  // Two passes over the corner tables. First every cell's own sums, written where its corner
  // will be (bands are independent: OpenCV's pool runs them side by side); then, band by band,
  // the prefix along x added to the row above, in place. The additions are the ones a single
  // pass would make, in the same order, so the tables are the same.
  const int* cell_of_x = x_axis_.floor_line.data();  // x < width: index of its cell
  const auto hist_at = [&](int line_y, int line_x) {
    return hist_corners_.get() +
           (static_cast<std::size_t>(line_y) * lines_x + line_x) * kColourHistBins;
  };
  const auto moments_at = [&](int line_y, int line_x) {
    return moment_corners_.get() + (static_cast<std::size_t>(line_y) * lines_x + line_x) * 6;
  };
  cv::parallel_for_(cv::Range(0, lines_y - 1), [&](const cv::Range& bands) {
    for (int band = bands.start; band < bands.end; ++band) {
      for (int y = y_axis_.lines[band]; y < y_axis_.lines[band + 1]; ++y) {
        const PixelCode* code = row_major_.get() + static_cast<std::size_t>(y) * size_.width;
        for (int x = 0; x < size_.width; ++x, ++code) {
          const int cell = cell_of_x[x];
          std::uint16_t* hist = hist_at(band + 1, cell + 1);
          ++hist[code->bins[0]];
          ++hist[code->bins[1]];
          ++hist[code->bins[2]];
          const cv::Vec3f hsv = HsvFromLevels(code->max_level, code->delta, code->hue_units);
          double* m = moments_at(band + 1, cell + 1);
          for (int c = 0; c < 3; ++c) {
            m[c] += hsv[c];
            m[3 + c] += static_cast<double>(hsv[c]) * hsv[c];
          }
        }
      }
    }
  });
  for (int band = 0; band + 1 < lines_y; ++band) {
    std::array<std::uint16_t, kColourHistBins> running_hist{};
    std::array<double, 6> running_moments{};
    for (int cell = 0; cell < cells_x; ++cell) {
      const std::uint16_t* above = hist_at(band, cell + 1);
      std::uint16_t* here = hist_at(band + 1, cell + 1);  // holds the cell's own counts
      for (int bin = 0; bin < kColourHistBins; ++bin) {
        running_hist[bin] = static_cast<std::uint16_t>(running_hist[bin] + here[bin]);
        here[bin] = static_cast<std::uint16_t>(above[bin] + running_hist[bin]);  // mod 65536
      }
      const double* above_m = moments_at(band, cell + 1);
      double* here_m = moments_at(band + 1, cell + 1);
      for (int k = 0; k < 6; ++k) {
        running_moments[k] += here_m[k];
        here_m[k] = above_m[k] + running_moments[k];
      }
    }
  }
}

template <typename Visit>
void ColourIntegrals::ForEachSpan(const cv::Rect& rect, Visit&& visit) const {
  if (rect.empty()) return;
  if (rect.width >= rect.height) {
    for (int y = rect.y; y < rect.y + rect.height; ++y) {
      visit(row_major_.get() + static_cast<std::size_t>(y) * size_.width + rect.x, rect.width);
    }
  } else {
    for (int x = rect.x; x < rect.x + rect.width; ++x) {
      visit(column_major_.get() + static_cast<std::size_t>(x) * size_.height + rect.y, rect.height);
    }
  }
}

const std::uint16_t* ColourIntegrals::HistCorner(int line_y, int line_x) const {
  const std::size_t lines_x = x_axis_.lines.size();
  return hist_corners_.get() +
         (static_cast<std::size_t>(line_y) * lines_x + line_x) * kColourHistBins;
}

const double* ColourIntegrals::MomentCorner(int line_y, int line_x) const {
  const std::size_t lines_x = x_axis_.lines.size();
  return moment_corners_.get() + (static_cast<std::size_t>(line_y) * lines_x + line_x) * 6;
}

void ColourIntegrals::AddAlignedHistogram(int ly0, int ly1, int lx0, int lx1,
                                          ColourHistogram& hist) const {
  // Counts wrap modulo 65536 in the corners, so each lookup must cover fewer than 65536 pixels:
  // split the cell rectangle into tiles of at most kMaxCellsPerTile cells.
  const int tile_w = std::min(lx1 - lx0, kMaxCellsPerTile);
  const int tile_h = std::max(1, kMaxCellsPerTile / tile_w);
  for (int ty = ly0; ty < ly1; ty += tile_h) {
    const int ty1 = std::min(ly1, ty + tile_h);
    for (int tx = lx0; tx < lx1; tx += tile_w) {
      const int tx1 = std::min(lx1, tx + tile_w);
      const std::uint16_t* tl = HistCorner(ty, tx);
      const std::uint16_t* tr = HistCorner(ty, tx1);
      const std::uint16_t* bl = HistCorner(ty1, tx);
      const std::uint16_t* br = HistCorner(ty1, tx1);
      for (int bin = 0; bin < kColourHistBins; ++bin) {
        hist[bin] += static_cast<std::uint16_t>(br[bin] - tr[bin] - bl[bin] + tl[bin]);
      }
    }
  }
}

ColourIntegrals::Split ColourIntegrals::Decompose(const cv::Rect& rect) const {
  Split split;
  split.lx0 = x_axis_.ceil_line[rect.x];
  split.lx1 = x_axis_.floor_line[rect.x + rect.width];
  split.ly0 = y_axis_.ceil_line[rect.y];
  split.ly1 = y_axis_.floor_line[rect.y + rect.height];
  split.has_inner = split.lx0 < split.lx1 && split.ly0 < split.ly1;
  if (!split.has_inner) {  // narrower than a cell in some direction: scan it all
    split.strips[0] = rect;
    return split;
  }
  const int ix0 = x_axis_.lines[split.lx0], ix1 = x_axis_.lines[split.lx1];
  const int iy0 = y_axis_.lines[split.ly0], iy1 = y_axis_.lines[split.ly1];
  const int x1 = rect.x + rect.width, y1 = rect.y + rect.height;
  split.strips = {cv::Rect(rect.x, rect.y, rect.width, iy0 - rect.y),  // top
                  cv::Rect(rect.x, iy1, rect.width, y1 - iy1),         // bottom
                  cv::Rect(rect.x, iy0, ix0 - rect.x, iy1 - iy0),      // left
                  cv::Rect(ix1, iy0, x1 - ix1, iy1 - iy0)};            // right
  return split;
}

ColourHistogram ColourIntegrals::Histogram(const cv::Rect& rect) const {
  ColourHistogram hist{};
  if (rect.empty()) return hist;
  const Split split = Decompose(rect);
  if (split.has_inner) AddAlignedHistogram(split.ly0, split.ly1, split.lx0, split.lx1, hist);
  // The strips are counted into four partial histograms, pixel i into part i % 4. Neighbouring
  // pixels of a smooth image mostly fall into the same bins, and with a single histogram every
  // increment waits for the store of the previous one (store-to-load forwarding); four
  // independent counters let them overlap. The counts are integers, so the merged histogram is
  // the same as counting pixel by pixel.
  std::array<ColourHistogram, 4> parts{};
  for (const cv::Rect& strip : split.strips) {
    ForEachSpan(strip, [&parts](const PixelCode* code, int n) {
      int i = 0;
      for (; i + 4 <= n; i += 4) {
        for (int k = 0; k < 4; ++k) {
          ++parts[k][code[i + k].bins[0]];
          ++parts[k][code[i + k].bins[1]];
          ++parts[k][code[i + k].bins[2]];
        }
      }
      for (; i < n; ++i) {
        ++parts[0][code[i].bins[0]];
        ++parts[0][code[i].bins[1]];
        ++parts[0][code[i].bins[2]];
      }
    });
  }
  for (int bin = 0; bin < kColourHistBins; ++bin) {
    hist[bin] += (parts[0][bin] + parts[1][bin]) + (parts[2][bin] + parts[3][bin]);
  }
  return hist;
}

ColourMoments ColourIntegrals::Moments(const cv::Rect& rect) const {
  ColourMoments moments{};
  if (rect.empty()) return moments;
  const Split split = Decompose(rect);
  if (split.has_inner) {
    const double* tl = MomentCorner(split.ly0, split.lx0);
    const double* tr = MomentCorner(split.ly0, split.lx1);
    const double* bl = MomentCorner(split.ly1, split.lx0);
    const double* br = MomentCorner(split.ly1, split.lx1);
    for (int k = 0; k < 6; ++k) moments[k] = br[k] - tr[k] - bl[k] + tl[k];
  }
  // One double addition per pixel in a fixed order (strips top, bottom, left, right; each along
  // its longer side): the sums round, so this order is part of the result.
  for (const cv::Rect& strip : split.strips) {
    ForEachSpan(strip, [&moments](const PixelCode* code, int n) {
      for (int i = 0; i < n; ++i) {
        const cv::Vec3f hsv = HsvFromLevels(code[i].max_level, code[i].delta, code[i].hue_units);
        for (int c = 0; c < 3; ++c) {
          moments[c] += hsv[c];
          moments[3 + c] += static_cast<double>(hsv[c]) * hsv[c];
        }
      }
    });
  }
  return moments;
}

int ColourIntegrals::SnapCoordinate(const Axis& axis, int local) {
  const int global = axis.origin + local;
  const int snapped = FloorDiv(global + kColourCellSize / 2, kColourCellSize) * kColourCellSize;
  return snapped - axis.origin;
}

cv::Rect ColourIntegrals::SnapToGrid(const cv::Rect& rect, const cv::Rect& bounds) const {
  auto snap = [](const Axis& axis, int local, int lo, int hi) {
    return std::clamp(SnapCoordinate(axis, local), lo, hi);
  };
  const int x0 = snap(x_axis_, rect.x, bounds.x, bounds.x + bounds.width);
  const int x1 = snap(x_axis_, rect.x + rect.width, bounds.x, bounds.x + bounds.width);
  const int y0 = snap(y_axis_, rect.y, bounds.y, bounds.y + bounds.height);
  const int y1 = snap(y_axis_, rect.y + rect.height, bounds.y, bounds.y + bounds.height);
  return {x0, y0, x1 - x0, y1 - y0};
}

}  // namespace tod
