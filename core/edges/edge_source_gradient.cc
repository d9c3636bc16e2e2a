// "gradient" edge source: the zero-training fallback of ALGORITHM.md §3.4.
#include <algorithm>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/edges/edge_channels.h"
#include "core/edges/edge_source.h"

namespace tod {
namespace {

// One 8-bit grey level changes L/100 by about 0.004, so a real edge's gradient is far above this;
// smaller "scales" are float rounding of the smoothing filter on flat images and must not be
// normalised up to 1.
constexpr float kMinEdgeScale = 1e-4f;

// Exact value of rank floor(fraction * (n - 1)) in ascending order of the non-negative `values`
// whose maximum is `max_value`: a histogram finds the bin holding that rank, and only that bin's
// values are partially sorted (several times faster than nth_element over the whole map).
float Percentile(const cv::Mat1f& values, double fraction, float max_value) {
  const std::size_t count = values.total();
  if (count == 0 || max_value <= 0.f) return 0.f;
  const auto rank =
      static_cast<std::size_t>(std::clamp(fraction, 0.0, 1.0) * static_cast<double>(count - 1));
  constexpr int kBins = 1024;
  const float bins_per_unit = static_cast<float>(kBins) / max_value;
  const auto bin_of = [&](float v) {
    return std::min(static_cast<int>(v * bins_per_unit), kBins - 1);
  };
  std::vector<std::size_t> histogram(kBins, 0);
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) ++histogram[bin_of(row[x])];
  }
  std::size_t below = 0;
  int bin = 0;
  while (below + histogram[bin] <= rank) below += histogram[bin++];
  std::vector<float> in_bin;
  in_bin.reserve(histogram[bin]);
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) {
      if (bin_of(row[x]) == bin) in_bin.push_back(row[x]);
    }
  }
  const auto nth = in_bin.begin() + static_cast<std::ptrdiff_t>(rank - below);
  std::nth_element(in_bin.begin(), nth, in_bin.end());
  return *nth;
}

class GradientEdgeSource : public EdgeSource {
 public:
  explicit GradientEdgeSource(const GradientEdgeParams& params) : params_(params) {}

  cv::Mat1f Compute(const cv::Mat3b& bgr) const override {
    if (bgr.empty()) return {};
    const cv::Mat3f luv = TriangleSmooth(BgrToLuv(bgr), params_.smooth_radius);
    cv::Mat1f edge = ComputeColourGradient(luv, /*with_orientation=*/false).magnitude;
    double max_value = 0.0;
    cv::minMaxLoc(edge, nullptr, &max_value);
    float scale = Percentile(edge, params_.normalise_percentile, static_cast<float>(max_value));
    if (scale < kMinEdgeScale) {
      // Edges on fewer pixels than (1 - percentile) of the image: the percentile is ~0, so fall
      // back to the maximum rather than dividing by zero (a flat image stays all zero).
      scale = static_cast<float>(max_value);
    }
    if (scale < kMinEdgeScale) return cv::Mat1f::zeros(bgr.size());
    edge *= 1.f / scale;
    cv::min(edge, 1.f, edge);
    return edge;
  }

  EdgeKind kind() const override { return EdgeKind::kGradient; }

 private:
  GradientEdgeParams params_;
};

}  // namespace

std::unique_ptr<EdgeSource> CreateGradientEdgeSource(const GradientEdgeParams& params) {
  return std::make_unique<GradientEdgeSource>(params);
}

}  // namespace tod
