#include "core/features/box_features.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

namespace tod {
namespace {

// Hue bin edges in degrees (ALGORITHM.md §5). Bins are half-open [e_i, e_{i+1}); the 17th bin
// [345, 361) is red again and is merged into bin 0.
constexpr std::array<double, 18> kHueEdges = {0,   15,  25,  45,  55,  80,  108, 140, 165,
                                              190, 220, 255, 275, 290, 316, 330, 345, 361};

std::string SizeText(const cv::Size& s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

Status ValidateInput(const cv::Mat1f& region_map, const cv::Mat3b& region_bgr,
                     cv::Point region_origin, cv::Size image_size) {
  if (region_map.size() != region_bgr.size()) {
    return Status::InvalidArgument("BoxFeatureExtractor: region_map is " +
                                   SizeText(region_map.size()) + " but region_bgr is " +
                                   SizeText(region_bgr.size()) + "; they must match");
  }
  if (image_size.width <= 0 || image_size.height <= 0) {
    return Status::InvalidArgument("BoxFeatureExtractor: image_size " + SizeText(image_size) +
                                   " must be positive");
  }
  if (region_origin.x < 0 || region_origin.y < 0 ||
      region_origin.x + region_map.cols > image_size.width ||
      region_origin.y + region_map.rows > image_size.height) {
    return Status::InvalidArgument(
        "BoxFeatureExtractor: region crop " + SizeText(region_map.size()) + " at (" +
        std::to_string(region_origin.x) + ", " + std::to_string(region_origin.y) +
        ") does not lie inside the image of size " + SizeText(image_size));
  }
  if (!region_map.empty() && !cv::checkRange(region_map)) {
    return Status::InvalidArgument("BoxFeatureExtractor: region_map contains NaN or infinity");
  }
  return Status::Ok();
}

// Sum of an integral image over the half-open rectangle r.
template <typename T>
double RectSum(const cv::Mat_<T>& integral, const cv::Rect& r) {
  const int x0 = r.x, y0 = r.y, x1 = r.x + r.width, y1 = r.y + r.height;
  return static_cast<double>(integral(y1, x1)) - static_cast<double>(integral(y0, x1)) -
         static_cast<double>(integral(y1, x0)) + static_cast<double>(integral(y0, x0));
}

double SafeDiv(double num, double den) { return den != 0.0 ? num / den : 0.0; }

// 1 - a.b / (|a||b|) over one channel's 16 bins; 0 when either histogram is all zero (the
// original gives NaN there, which [C-ROS] replaces by 0).
float CosineDistance(const int* a, const int* b, int bins) {
  double dot = 0.0, norm_a = 0.0, norm_b = 0.0;
  for (int i = 0; i < bins; ++i) {
    dot += static_cast<double>(a[i]) * b[i];
    norm_a += static_cast<double>(a[i]) * a[i];
    norm_b += static_cast<double>(b[i]) * b[i];
  }
  if (norm_a <= 0.0 || norm_b <= 0.0) return 0.f;
  return static_cast<float>(1.0 - dot / std::sqrt(norm_a * norm_b));
}

}  // namespace

cv::Vec3f BgrToHsv(const cv::Vec3b& bgr) {
  const double b = bgr[0] / 255.0, g = bgr[1] / 255.0, r = bgr[2] / 255.0;
  const double v = std::max({r, g, b});
  const double delta = v - std::min({r, g, b});
  if (delta <= 0.0) return {0.f, 0.f, static_cast<float>(v)};  // grey: hue and saturation 0
  double sextant;                                              // hue in units of 60 degrees, [0, 6)
  if (v == r) {
    sextant = (g - b) / delta;
    if (sextant < 0.0) sextant += 6.0;
  } else if (v == g) {
    sextant = 2.0 + (b - r) / delta;
  } else {
    sextant = 4.0 + (r - g) / delta;
  }
  return {static_cast<float>(sextant / 6.0), static_cast<float>(delta / v), static_cast<float>(v)};
}

int HueBin(double hue_degrees) {
  const auto upper = std::upper_bound(kHueEdges.begin(), kHueEdges.end(), hue_degrees);
  const int bin = static_cast<int>(upper - kHueEdges.begin()) - 1;
  if (bin < 0) return 0;          // below 0 degrees: cannot happen for rgb2hsv
  if (bin >= kHueBins) return 0;  // [345, 361) and beyond: red wrap-around
  return bin;
}

int SatValBin(float value) {
  // Width 1/16 is a power of two, so value * 16 is exact; 1.0 lands in bin 15 (last edge 1.1).
  const int bin = static_cast<int>(std::floor(value * static_cast<float>(kSatValBins)));
  return std::clamp(bin, 0, kSatValBins - 1);
}

BoxFeatureExtractor::BoxFeatureExtractor(const cv::Mat1f& region_map, const cv::Mat3b& region_bgr,
                                         cv::Point region_origin, cv::Size image_size,
                                         const BoxFeatureOptions& options)
    : status_(ValidateInput(region_map, region_bgr, region_origin, image_size)),
      options_(options),
      origin_(region_origin),
      image_size_(image_size) {
  if (!status_.ok()) return;  // empty extractor: every box misses the (empty) region
  region_size_ = region_map.size();
  const int rows = region_map.rows, cols = region_map.cols;

  // Features 4-7: sum of M and count of M > 0.
  cv::integral(region_map, map_sum_, CV_64F);
  cv::Mat1b edge_pixels = region_map > 0.f;
  edge_pixels.setTo(1, edge_pixels);
  cv::integral(edge_pixels, map_count_, CV_32S);

  // Features 1-3: edge pixels in compressed rows, values replaced by their rank.
  edge_row_start_.assign(rows + 1, 0);
  std::vector<float> pixel_values;  // value of each stored edge pixel
  for (int y = 0; y < rows; ++y) {
    const float* row = region_map[y];
    for (int x = 0; x < cols; ++x) {
      if (row[x] > 0.f) {
        edge_cols_.push_back(x);
        pixel_values.push_back(row[x]);
      }
    }
    edge_row_start_[y + 1] = static_cast<int>(edge_cols_.size());
  }
  edge_values_ = pixel_values;
  std::sort(edge_values_.begin(), edge_values_.end());
  edge_values_.erase(std::unique(edge_values_.begin(), edge_values_.end()), edge_values_.end());
  edge_ranks_.resize(pixel_values.size());
  for (std::size_t i = 0; i < pixel_values.size(); ++i) {
    edge_ranks_[i] = static_cast<int>(
        std::lower_bound(edge_values_.begin(), edge_values_.end(), pixel_values[i]) -
        edge_values_.begin());
  }

  // Colour: convert once (float HSV) and bin once, then integrate (features 15-20).
  std::array<cv::Mat1f, 3> hsv;
  for (auto& channel : hsv) channel.create(rows, cols);
  const std::size_t stride = static_cast<std::size_t>(cols + 1) * kColourHistBins;
  hist_integrals_ = std::make_unique_for_overwrite<std::int32_t[]>((rows + 1) * stride);
  std::fill_n(hist_integrals_.get(), stride, 0);  // row 0 of the integral
  std::array<std::int32_t, kColourHistBins> row_counts{};
  for (int y = 0; y < rows; ++y) {
    row_counts.fill(0);
    const std::int32_t* above = hist_integrals_.get() + static_cast<std::size_t>(y) * stride;
    std::int32_t* here = hist_integrals_.get() + static_cast<std::size_t>(y + 1) * stride;
    std::fill_n(here, kColourHistBins, 0);  // column 0 of the integral
    for (int x = 0; x < cols; ++x) {
      const cv::Vec3f pixel = BgrToHsv(region_bgr(y, x));
      hsv[0](y, x) = pixel[0];
      hsv[1](y, x) = pixel[1];
      hsv[2](y, x) = pixel[2];
      ++row_counts[HueBin(static_cast<double>(pixel[0]) * 360.0)];
      ++row_counts[kHueBins + SatValBin(pixel[1])];
      ++row_counts[kHueBins + kSatValBins + SatValBin(pixel[2])];
      const std::size_t at = static_cast<std::size_t>(x + 1) * kColourHistBins;
      for (int bin = 0; bin < kColourHistBins; ++bin) {
        here[at + bin] = above[at + bin] + row_counts[bin];
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    cv::integral(hsv[c], hsv_sum_[c], hsv_sq_sum_[c], CV_64F, CV_64F);
  }
}

Result<BoxFeatureExtractor> BoxFeatureExtractor::Create(const cv::Mat1f& region_map,
                                                        const cv::Mat3b& region_bgr,
                                                        cv::Point region_origin,
                                                        cv::Size image_size,
                                                        const BoxFeatureOptions& options) {
  BoxFeatureExtractor extractor(region_map, region_bgr, region_origin, image_size, options);
  if (!extractor.status().ok()) return extractor.status();
  return extractor;
}

std::array<int, kColourHistBins> BoxFeatureExtractor::HistogramOf(const cv::Rect& local) const {
  const std::size_t stride = static_cast<std::size_t>(region_size_.width + 1) * kColourHistBins;
  auto corner = [&](int y, int x) {
    return hist_integrals_.get() + static_cast<std::size_t>(y) * stride +
           static_cast<std::size_t>(x) * kColourHistBins;
  };
  const std::int32_t* top_left = corner(local.y, local.x);
  const std::int32_t* top_right = corner(local.y, local.x + local.width);
  const std::int32_t* bottom_left = corner(local.y + local.height, local.x);
  const std::int32_t* bottom_right = corner(local.y + local.height, local.x + local.width);
  std::array<int, kColourHistBins> hist{};
  for (int bin = 0; bin < kColourHistBins; ++bin) {
    hist[bin] = bottom_right[bin] - top_right[bin] - bottom_left[bin] + top_left[bin];
  }
  return hist;
}

BoxFeatureVector BoxFeatureExtractor::Compute(const Box& box, float objectness) const {
  BoxFeatureVector f{};
  f[9] = objectness;
  // Clip to the region crop, in region-local coordinates (ALGORITHM.md §5: "the box is first
  // clipped to the region"). No overlap: nothing to measure.
  const Box local_box = ClipToImage(Box{box.x - origin_.x, box.y - origin_.y, box.w, box.h},
                                    region_size_.width, region_size_.height);
  if (local_box.empty()) return f;
  const cv::Rect r = local_box.rect();
  const int w = r.width, h = r.height;
  const double area = static_cast<double>(w) * h;

  // Features 1-3 need the values themselves: visit the box's edge pixels, counting each value
  // rank. counts[] is all zero between calls (only touched entries are used and reset).
  thread_local std::vector<int> counts;
  thread_local std::vector<int> touched;
  if (counts.size() < edge_values_.size()) counts.resize(edge_values_.size(), 0);
  touched.clear();
  for (int y = r.y; y < r.y + h; ++y) {
    const auto row_begin = edge_cols_.begin() + edge_row_start_[y];
    const auto row_end = edge_cols_.begin() + edge_row_start_[y + 1];
    for (auto it = std::lower_bound(row_begin, row_end, r.x); it != row_end && *it < r.x + w;
         ++it) {
      const int rank = edge_ranks_[it - edge_cols_.begin()];
      if (counts[rank]++ == 0) touched.push_back(rank);
    }
  }
  if (!touched.empty()) {
    // Most frequent value; on ties the smallest value, i.e. the smallest rank.
    int mode_rank = touched.front(), max_rank = touched.front(), edge_count = 0;
    for (const int rank : touched) {
      edge_count += counts[rank];
      max_rank = std::max(max_rank, rank);
      if (counts[rank] > counts[mode_rank] ||
          (counts[rank] == counts[mode_rank] && rank < mode_rank)) {
        mode_rank = rank;
      }
    }
    f[0] = edge_values_[max_rank];
    f[1] = edge_values_[mode_rank];
    f[2] = static_cast<float>(static_cast<double>(counts[mode_rank]) / edge_count);
    for (const int rank : touched) counts[rank] = 0;
  }

  // Features 4-5: the centre sub-box (half width, half height, same centre; the code's
  // "inner ring", ALGORITHM.md §10 #10), normalised by A/4 as in the original.
  const int inner_w = w / 2, inner_h = h / 2;
  const cv::Rect inner(r.x + (w - inner_w) / 2, r.y + (h - inner_h) / 2, inner_w, inner_h);
  f[3] = static_cast<float>(SafeDiv(RectSum(map_sum_, inner), area / 4.0));
  f[4] = static_cast<float>(SafeDiv(RectSum(map_count_, inner), area / 4.0));
  // Features 6-7 over the whole box.
  f[5] = static_cast<float>(RectSum(map_sum_, r) / area);
  f[6] = static_cast<float>(RectSum(map_count_, r) / area);

  // Features 8-9, 11-14: pseudodistance, normalised by the actual image size (§10 #23).
  const double image_w = image_size_.width, image_h = image_size_.height;
  const int x_for_centre = options_.region_relative_centre ? r.x : r.x + origin_.x;
  const int y_for_centre = options_.region_relative_centre ? r.y : r.y + origin_.y;
  f[7] = static_cast<float>(area / (image_w * image_h));
  f[8] = static_cast<float>(static_cast<double>(w) / h);
  f[10] = static_cast<float>((x_for_centre + w / 2.0) / image_w);
  f[11] = static_cast<float>((y_for_centre + h / 2.0) / image_h);
  f[12] = static_cast<float>(w / image_w);
  f[13] = static_cast<float>(h / image_h);

  // Features 15-17: population standard deviation of H, S, V.
  for (int c = 0; c < 3; ++c) {
    const double mean = RectSum(hsv_sum_[c], r) / area;
    const double variance = RectSum(hsv_sq_sum_[c], r) / area - mean * mean;
    f[14 + c] = static_cast<float>(std::sqrt(std::max(0.0, variance)));
  }

  // Features 18-20: histogram of the box against its surround ring = (box grown by w/2 left and
  // right, h/2 top and bottom, clipped to the crop) minus the box.
  const int grow_x = w / 2, grow_y = h / 2;
  const Box grown = ClipToImage(Box{r.x - grow_x, r.y - grow_y, w + 2 * grow_x, h + 2 * grow_y},
                                region_size_.width, region_size_.height);
  const std::array<int, kColourHistBins> box_hist = HistogramOf(r);
  std::array<int, kColourHistBins> ring_hist = HistogramOf(grown.rect());
  for (int bin = 0; bin < kColourHistBins; ++bin) ring_hist[bin] -= box_hist[bin];
  f[17] = CosineDistance(box_hist.data(), ring_hist.data(), kHueBins);
  f[18] = CosineDistance(box_hist.data() + kHueBins, ring_hist.data() + kHueBins, kSatValBins);
  f[19] = CosineDistance(box_hist.data() + kHueBins + kSatValBins,
                         ring_hist.data() + kHueBins + kSatValBins, kSatValBins);
  return f;
}

cv::Mat1f BoxFeatureExtractor::ComputeAll(const std::vector<ScoredBox>& proposals) const {
  cv::Mat1f features(static_cast<int>(proposals.size()), kNumBoxFeatures);
  for (int i = 0; i < features.rows; ++i) {
    const BoxFeatureVector f = Compute(proposals[i].box, proposals[i].score);
    std::copy(f.begin(), f.end(), features[i]);
  }
  return features;
}

}  // namespace tod
