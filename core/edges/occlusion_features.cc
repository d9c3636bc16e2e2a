#include "core/edges/occlusion_features.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/core/hal/hal.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "core/base/row_bands.h"

namespace tod {
namespace {

constexpr int kColourBins = 16;  // per HSV channel
constexpr int kTextureBins = 8;  // gradient orientations over [0, π)

// Appearance summary of one superpixel; histograms are normalised once accumulation ends.
struct RegionStats {
  double area = 0.0;
  double sum_y = 0.0;
  std::array<double, 3> sum_luv{};
  std::array<float, 3 * kColourBins> hsv_hist{};
  std::array<float, kTextureBins> texture_hist{};
};

// Gradient magnitude and texture bin of every pixel of one row, in two loops that vectorise
// (the per-pixel version was scalar: std::sqrt may set errno, and the fold was a branch).
// cv::hal::sqrt32f takes SIMD square roots, correctly rounded like std::sqrt. Orientation is
// taken mod π: the gradient is folded into the upper half plane, then its bin is the number of
// bin edges kπ/8 it lies counter-clockwise of (no atan2 per pixel). The bin is meaningful only
// where the magnitude is > 0.
void TextureRow(const float* __restrict gx, const float* __restrict gy, int cols,
                const std::array<float, kTextureBins - 1>& edge_cos,
                const std::array<float, kTextureBins - 1>& edge_sin, float* __restrict magnitude,
                int* __restrict bin) {
  for (int x = 0; x < cols; ++x) magnitude[x] = gx[x] * gx[x] + gy[x] * gy[x];
  cv::hal::sqrt32f(magnitude, magnitude, cols);
  for (int x = 0; x < cols; ++x) {
    const bool flip = gy[x] < 0.f || (gy[x] == 0.f && gx[x] < 0.f);
    const float gxv = flip ? -gx[x] : gx[x];
    const float gyv = flip ? -gy[x] : gy[x];
    int b = 0;
    for (int k = 0; k < kTextureBins - 1; ++k) {
      b += edge_cos[k] * gyv - edge_sin[k] * gxv >= 0.f ? 1 : 0;
    }
    bin[x] = b;
  }
}

// The image as the regions' appearance reads it: LUV and HSV bytes and the Sobel derivatives.
struct AppearanceImages {
  cv::Mat3b luv;
  cv::Mat3b hsv;  // 8-bit: H in [0,180), S and V in [0,256)
  cv::Mat gx16;
  cv::Mat gy16;
};

// The colour conversions are per pixel, so they run in bands of rows on OpenCV's pool with the
// pixels of whole-image calls (row_bands.h). They run before the region statistics and the
// boundary scan, which then run side by side: inside that pair, OpenCV's own splitting of
// cv::cvtColor ran on one thread.
AppearanceImages ConvertForAppearance(const cv::Mat3b& image) {
  AppearanceImages out;
  out.luv.create(image.size());
  out.hsv.create(image.size());
  cv::Mat1b gray(image.size());
  ForEachRowBand(image.rows, [&](const cv::Range& rows) {
    cv::Mat luv_band = out.luv.rowRange(rows);
    cv::Mat hsv_band = out.hsv.rowRange(rows);
    cv::Mat gray_band = gray.rowRange(rows);
    const cv::Mat3b image_band = image.rowRange(rows);
    cv::cvtColor(image_band, luv_band, cv::COLOR_BGR2Luv);
    cv::cvtColor(image_band, hsv_band, cv::COLOR_BGR2HSV);
    cv::cvtColor(image_band, gray_band, cv::COLOR_BGR2GRAY);
  });
  // The 3x3 Sobel derivatives of an 8-bit image are integers in [-1020, 1020]: cv::Sobel into
  // CV_32F and cv::spatialGradient into CV_16S compute the same integers (same kernels, same
  // BORDER_DEFAULT border), and int16 -> float is exact. spatialGradient does both derivatives
  // in one pass over the image instead of two separable filters each.
  cv::spatialGradient(gray, out.gx16, out.gy16, 3, cv::BORDER_DEFAULT);
  return out;
}

std::vector<RegionStats> ComputeRegionStats(const AppearanceImages& appearance,
                                            const cv::Mat1i& labels, int count) {
  const cv::Mat3b& luv = appearance.luv;
  const cv::Mat3b& hsv = appearance.hsv;
  const cv::Mat& gx16 = appearance.gx16;
  const cv::Mat& gy16 = appearance.gy16;

  // Integer sums per region while scanning (see the loop below); RegionStats at the end.
  struct Sums {
    std::int64_t area = 0;
    std::int64_t sum_y = 0;
    std::array<std::int64_t, 3> sum_luv{};
    std::array<std::int32_t, 3 * kColourBins> hsv_count{};
  };
  std::vector<Sums> sums(static_cast<size_t>(count) + 1);
  std::vector<RegionStats> stats(static_cast<size_t>(count) + 1);
  // Directions of the inner texture-bin edges kπ/8, k = 1..7.
  std::array<float, kTextureBins - 1> edge_cos{};
  std::array<float, kTextureBins - 1> edge_sin{};
  for (int k = 0; k < kTextureBins - 1; ++k) {
    edge_cos[k] = static_cast<float>(std::cos((k + 1) * CV_PI / kTextureBins));
    edge_sin[k] = static_cast<float>(std::sin((k + 1) * CV_PI / kTextureBins));
  }
  const int cols = labels.cols;
  std::vector<float> gx(static_cast<size_t>(cols));
  std::vector<float> gy(static_cast<size_t>(cols));
  std::vector<float> magnitude(static_cast<size_t>(cols));
  std::vector<int> texture_bin(static_cast<size_t>(cols));
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels[y];
    const cv::Vec3b* luv_row = luv.ptr<cv::Vec3b>(y);
    const cv::Vec3b* hsv_row = hsv.ptr<cv::Vec3b>(y);
    const std::int16_t* gx_row = gx16.ptr<std::int16_t>(y);
    const std::int16_t* gy_row = gy16.ptr<std::int16_t>(y);
    for (int x = 0; x < cols; ++x) {
      gx[x] = gx_row[x];
      gy[x] = gy_row[x];
    }
    TextureRow(gx.data(), gy.data(), cols, edge_cos, edge_sin, magnitude.data(),
               texture_bin.data());
    // One run of equal labels at a time: the region is looked up once per run and its area,
    // row and LUV sums are kept in registers (the former per-pixel double additions to memory
    // formed one long store-to-load chain). These sums are integers, exact in any order; the
    // texture sums are float and stay one addition per pixel in pixel order.
    for (int x = 0; x < cols;) {
      const int label = l[x];
      if (label <= 0) {
        ++x;
        continue;
      }
      int end = x + 1;
      while (end < cols && l[end] == label) ++end;
      Sums& s = sums[label];
      RegionStats& r = stats[label];
      std::array<std::int64_t, 3> luv_sum = s.sum_luv;
      for (int i = x; i < end; ++i) {
        for (int c = 0; c < 3; ++c) luv_sum[c] += luv_row[i][c];
        ++s.hsv_count[hsv_row[i][0] * kColourBins / 180];
        ++s.hsv_count[kColourBins + hsv_row[i][1] * kColourBins / 256];
        ++s.hsv_count[2 * kColourBins + hsv_row[i][2] * kColourBins / 256];
        if (magnitude[i] > 0.f) r.texture_hist[texture_bin[i]] += magnitude[i];
      }
      s.sum_luv = luv_sum;
      s.area += end - x;
      s.sum_y += static_cast<std::int64_t>(y) * (end - x);
      x = end;
    }
  }
  // The former code summed 1.0, y and the LUV bytes into doubles (exact: integers far below
  // 2^53) and counted the histograms with float += 1.f, which is exact up to 2^24 and then stays
  // at 2^24 (2^24 + 1 rounds to even); min(count, 2^24) reproduces that.
  constexpr std::int32_t kFloatCountLimit = std::int32_t{1} << std::numeric_limits<float>::digits;
  for (size_t i = 0; i < stats.size(); ++i) {
    RegionStats& s = stats[i];
    const Sums& t = sums[i];
    s.area = static_cast<double>(t.area);
    s.sum_y = static_cast<double>(t.sum_y);
    for (int c = 0; c < 3; ++c) s.sum_luv[c] = static_cast<double>(t.sum_luv[c]);
    for (int b = 0; b < 3 * kColourBins; ++b) {
      s.hsv_hist[b] = static_cast<float>(std::min(t.hsv_count[b], kFloatCountLimit));
    }
    if (s.area > 0) {
      for (float& v : s.hsv_hist) v /= static_cast<float>(s.area);
    }
    float texture_total = 0.f;
    for (float v : s.texture_hist) texture_total += v;
    if (texture_total > 0.f) {
      for (float& v : s.texture_hist) v /= texture_total;
    }
  }
  return stats;
}

// Finds or creates the index of pair (a, b), a < b, via per-label adjacency lists (a superpixel
// has a handful of neighbours, so a linear scan beats hashing).
int PairIndex(int a, int b, std::vector<std::vector<cv::Vec2i>>& adjacency,
              std::vector<cv::Vec2i>& pairs) {
  for (const cv::Vec2i& entry : adjacency[a]) {
    if (entry[0] == b) return entry[1];
  }
  const int index = static_cast<int>(pairs.size());
  pairs.emplace_back(a, b);
  adjacency[a].emplace_back(b, index);
  return index;
}

}  // namespace

float ChiSquaredDistance(const float* p, const float* q, int bins) {
  float sum = 0.f;
  for (int i = 0; i < bins; ++i) {
    const float total = p[i] + q[i];
    if (total > 0.f) sum += (p[i] - q[i]) * (p[i] - q[i]) / total;
  }
  return 0.5f * sum;
}

namespace {

// The distinct positive labels around a pixel, sorted (at most 8).
struct NeighbourLabels {
  std::array<int, 9> labels{};  // 8 neighbours + the centre slot
  int count = 0;
  // Inserts t keeping `labels` sorted and distinct: the set does not depend on the order of the
  // neighbours.
  void Insert(int t) {
    if (t <= 0) return;
    int pos = 0;
    while (pos < count && labels[pos] < t) ++pos;
    if (pos < count && labels[pos] == t) return;
    for (int m = count; m > pos; --m) labels[m] = labels[m - 1];
    labels[pos] = t;
    ++count;
  }
};

// The labels of pixel (x, y)'s 8-neighbourhood; above / below are the neighbouring rows (null
// outside the image).
NeighbourLabels LabelsAround(const cv::Mat1i& labels, int x, int y, const int* above,
                             const int* row, const int* below) {
  NeighbourLabels seen;
  if (above != nullptr && below != nullptr && x > 0 && x + 1 < labels.cols) {
    // Interior pixel: the eight neighbours without bounds checks (the centre is 0).
    seen.Insert(above[x - 1]);
    seen.Insert(above[x]);
    seen.Insert(above[x + 1]);
    seen.Insert(row[x - 1]);
    seen.Insert(row[x + 1]);
    seen.Insert(below[x - 1]);
    seen.Insert(below[x]);
    seen.Insert(below[x + 1]);
    return seen;
  }
  for (int dy = -1; dy <= 1; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= labels.rows) continue;
    const int* nrow = labels[yy];
    for (int dx = -1; dx <= 1; ++dx) {
      const int xx = x + dx;
      if (xx < 0 || xx >= labels.cols) continue;
      seen.Insert(nrow[xx]);
    }
  }
  return seen;
}

// Step 1: the boundary pixels, the pairs each borders (CSR, in `out`) and their coordinates.
std::vector<cv::Point> ScanBoundaries(const Superpixels& superpixels, SuperpixelPairs& out) {
  const cv::Mat1i& labels = superpixels.labels;
  const int width = labels.cols;
  const int height = labels.rows;
  out.pixel_offsets.push_back(0);
  std::vector<std::vector<cv::Vec2i>> adjacency(static_cast<size_t>(superpixels.count) + 1);
  // Consecutive boundary pixels nearly always border the same pair: a one-entry cache in front
  // of PairIndex skips the adjacency scan. PairIndex returns the same index for a pair every
  // time after its first call, so the cache changes nothing.
  int cached_a = -1, cached_b = -1, cached_index = -1;
  auto pair_index = [&](int a, int b) {
    if (a != cached_a || b != cached_b) {
      cached_a = a;
      cached_b = b;
      cached_index = PairIndex(a, b, adjacency, out.pairs);
    }
    return cached_index;
  };
  // Coordinates of every boundary pixel, so that the per-pair loops need no division of the flat
  // index.
  std::vector<cv::Point> boundary_points;
  for (int y = 0; y < height; ++y) {
    const int* row = labels[y];
    const int* above = y > 0 ? labels[y - 1] : nullptr;
    const int* below = y + 1 < height ? labels[y + 1] : nullptr;
    for (int x = 0; x < width; ++x) {
      if (row[x] != 0) continue;
      const NeighbourLabels seen = LabelsAround(labels, x, y, above, row, below);
      if (seen.count < 2) continue;
      for (int i = 0; i < seen.count; ++i) {
        for (int j = i + 1; j < seen.count; ++j) {
          out.pixel_pairs.push_back(pair_index(seen.labels[i], seen.labels[j]));
        }
      }
      out.boundary_pixels.push_back(y * width + x);
      boundary_points.emplace_back(x, y);
      out.pixel_offsets.push_back(static_cast<int>(out.pixel_pairs.size()));
    }
  }
  return boundary_points;
}

// Step 2: every pair's boundary pixels, in boundary order (a counting sort by pair).
struct PairPixels {
  std::vector<int> offsets;  // pair p: points[offsets[p] .. offsets[p + 1])
  std::vector<cv::Point> points;
};

PairPixels InvertToPairs(const SuperpixelPairs& pairs,
                         const std::vector<cv::Point>& boundary_points) {
  const int num_pairs = static_cast<int>(pairs.pairs.size());
  PairPixels out;
  out.offsets.assign(static_cast<size_t>(num_pairs) + 1, 0);
  for (int p : pairs.pixel_pairs) ++out.offsets[p + 1];
  for (int p = 0; p < num_pairs; ++p) out.offsets[p + 1] += out.offsets[p];
  out.points.resize(pairs.pixel_pairs.size());
  std::vector<int> cursor(out.offsets.begin(), out.offsets.end() - 1);
  for (size_t i = 0; i < boundary_points.size(); ++i) {
    for (int k = pairs.pixel_offsets[i]; k < pairs.pixel_offsets[i + 1]; ++k) {
      out.points[cursor[pairs.pixel_pairs[k]]++] = boundary_points[i];
    }
  }
  return out;
}

// Step 3: the features of pair p (row f) from its boundary pixels and its two regions' stats.
// `values` is scratch.
void PairFeatures(const cv::Mat1f& enhanced_edge, const PairPixels& pixels,
                  const std::vector<RegionStats>& regions, const cv::Vec2i& pair, int p,
                  float inv_height, std::vector<float>& values, float* f) {
  const int begin = pixels.offsets[p];
  const int end = pixels.offsets[p + 1];
  const int length = end - begin;
  values.clear();
  double sum_x = 0.0;
  double sum_y = 0.0;
  for (int k = begin; k < end; ++k) {
    const cv::Point pixel = pixels.points[k];
    values.push_back(enhanced_edge(pixel.y, pixel.x));
    sum_x += pixel.x;
    sum_y += pixel.y;
  }
  const double mean_x = sum_x / length;
  const double mean_y = sum_y / length;
  double sxx = 0.0;
  double syy = 0.0;
  double sxy = 0.0;
  for (int k = begin; k < end; ++k) {
    const double dx = pixels.points[k].x - mean_x;
    const double dy = pixels.points[k].y - mean_y;
    sxx += dx * dx;
    syy += dy * dy;
    sxy += dx * dy;
  }
  float edge_sum = 0.f;
  float edge_max = 0.f;
  for (float v : values) {
    edge_sum += v;
    edge_max = std::max(edge_max, v);
  }
  std::nth_element(values.begin(), values.begin() + length / 2, values.end());
  f[kEdgeMean] = edge_sum / static_cast<float>(length);
  f[kEdgeMax] = edge_max;
  f[kEdgeMedian] = values[length / 2];
  f[kBoundaryLength] = static_cast<float>(length);
  f[kBoundaryOrientation] = static_cast<float>(std::abs(0.5 * std::atan2(2.0 * sxy, sxx - syy)));
  f[kBoundaryY] = static_cast<float>(mean_y) * inv_height;

  const RegionStats* small = &regions[pair[0]];
  const RegionStats* large = &regions[pair[1]];
  if (small->area > large->area) std::swap(small, large);
  f[kAreaSmaller] = static_cast<float>(small->area);
  f[kAreaLarger] = static_cast<float>(large->area);
  double norm2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double diff = std::abs(small->sum_luv[c] / small->area - large->sum_luv[c] / large->area);
    f[kLuvDiffL + c] = static_cast<float>(diff);
    norm2 += diff * diff;
  }
  f[kLuvDiffNorm] = static_cast<float>(std::sqrt(norm2));
  for (int c = 0; c < 3; ++c) {
    f[kHueChi2 + c] = ChiSquaredDistance(small->hsv_hist.data() + c * kColourBins,
                                         large->hsv_hist.data() + c * kColourBins, kColourBins);
  }
  f[kTextureChi2] =
      ChiSquaredDistance(small->texture_hist.data(), large->texture_hist.data(), kTextureBins);
  f[kVerticalOrder] =
      static_cast<float>(small->sum_y / small->area - large->sum_y / large->area) * inv_height;
}

// Pairs per piece of the parallel feature loop: a real frame has ~16 000 pairs.
constexpr int kPairsPerPiece = 1024;

}  // namespace

SuperpixelPairs ComputeSuperpixelPairs(const cv::Mat3b& image, const cv::Mat1f& enhanced_edge,
                                       const Superpixels& superpixels) {
  SuperpixelPairs out;
  // The regions' appearance and the boundary scan read the same labels and nothing of each
  // other: on OpenCV's pool they run side by side (one after the other on one thread), each
  // computing exactly what it computes alone.
  const AppearanceImages appearance = ConvertForAppearance(image);
  std::vector<RegionStats> regions;
  std::vector<cv::Point> boundary_points;
  cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& tasks) {
    for (int task = tasks.start; task < tasks.end; ++task) {
      if (task == 0)
        regions = ComputeRegionStats(appearance, superpixels.labels, superpixels.count);
      else
        boundary_points = ScanBoundaries(superpixels, out);
    }
  });
  const PairPixels pixels = InvertToPairs(out, boundary_points);
  const int num_pairs = static_cast<int>(out.pairs.size());
  out.features = cv::Mat1f(num_pairs, kNumOcclusionFeatures, 0.f);
  const float inv_height = 1.f / static_cast<float>(superpixels.labels.rows);
  // Every pair writes only its own row.
  const int pieces = (num_pairs + kPairsPerPiece - 1) / kPairsPerPiece;
  cv::parallel_for_(cv::Range(0, pieces), [&](const cv::Range& range) {
    std::vector<float> values;
    for (int p = range.start * kPairsPerPiece; p < std::min(num_pairs, range.end * kPairsPerPiece);
         ++p)
      PairFeatures(enhanced_edge, pixels, regions, out.pairs[p], p, inv_height, values,
                   out.features[p]);
  });
  return out;
}

}  // namespace tod
