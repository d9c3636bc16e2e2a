// "pixel_forest" edge source: the trained base edge map of ALGORITHM.md §3.4, "Preferred
// pipeline" step 1. Everything (channels, samples, predictions) lives on the stride-2 cell grid
// of edge_channels.h, as SED evaluates at stride 2; Compute() upsamples bilinearly.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/row_bands.h"
#include "core/edges/edge_channels.h"
#include "core/edges/edge_labels.h"
#include "core/edges/edge_pixel_features.h"
#include "core/edges/edge_source.h"

namespace tod {
namespace {

constexpr std::string_view kMagic("TODPXEDG", 8);
constexpr std::uint32_t kFormatVersion = 1;
constexpr std::uint32_t kMaxSmoothRadius = 16;  // sanity bound when loading

// A cell is a positive sample when at least half of its 2x2 pixels are near a boundary.
constexpr float kPositiveNearFraction = 0.5f;

// Picks up to `count` distinct entries of `pool` (partial Fisher-Yates).
std::vector<int> SampleWithoutReplacement(std::vector<int> pool, std::size_t count,
                                          std::mt19937_64& rng) {
  count = std::min(count, pool.size());
  for (std::size_t i = 0; i < count; ++i) {
    std::uniform_int_distribution<std::size_t> pick(i, pool.size() - 1);
    std::swap(pool[i], pool[pick(rng)]);
  }
  pool.resize(count);
  return pool;
}

Status CheckFrame(const EdgeTrainingFrame& frame, std::size_t index) {
  const std::string name = "edge training frame " + std::to_string(index);
  if (frame.image.empty()) return Status::InvalidArgument(name + ": image is empty");
  if (frame.labels.size() != frame.image.size()) {
    return Status::InvalidArgument(name + ": labels are " + std::to_string(frame.labels.cols) +
                                   "x" + std::to_string(frame.labels.rows) + " but the image is " +
                                   std::to_string(frame.image.cols) + "x" +
                                   std::to_string(frame.image.rows));
  }
  return Status::Ok();
}

}  // namespace

Result<EdgeSamples> ExtractEdgeSamples(const EdgeTrainingFrame& frame,
                                       const PixelEdgeParams& params, std::size_t frame_index) {
  if (params.samples_per_frame < 2) {
    return Status::InvalidArgument("pixel edge training: samples_per_frame must be >= 2");
  }
  if (!(params.negatives_per_positive > 0.0 && params.negatives_per_positive <= 1000.0)) {
    return Status::InvalidArgument(
        "pixel edge training: negatives_per_positive must be in (0, 1000]");
  }
  if (Status status = CheckFrame(frame, frame_index); !status.ok()) return status;
  const int num_features = NumPixelFeatures();
  const std::size_t per_class = static_cast<std::size_t>(params.samples_per_frame / 2);
  EdgeSamples out;
  out.features.create(0, num_features);
  const CellLabels cells = ComputeCellLabels(frame.labels, params.boundary_radius);
  std::vector<int> positive_cells;
  std::vector<int> negative_cells;
  for (int i = 0; i < cells.near_fraction.rows; ++i) {
    for (int j = 0; j < cells.near_fraction.cols; ++j) {
      if (cells.void_fraction(i, j) > params.max_void_fraction) continue;
      const int index = i * cells.near_fraction.cols + j;
      (cells.near_fraction(i, j) >= kPositiveNearFraction ? positive_cells : negative_cells)
          .push_back(index);
    }
  }
  // The same number of positives as the frame has negatives to match (negatives_per_positive
  // of them each), so every frame weighs alike in both classes.
  const double ratio = params.negatives_per_positive;
  const std::size_t positives =
      std::min({per_class, positive_cells.size(),
                static_cast<std::size_t>(static_cast<double>(negative_cells.size()) / ratio)});
  const std::size_t negatives =
      std::min(negative_cells.size(), static_cast<std::size_t>(std::llround(ratio * positives)));
  if (positives == 0 || negatives == 0) return out;
  out.positive_cells = static_cast<double>(positive_cells.size());
  out.negative_cells = static_cast<double>(negative_cells.size());
  out.positives_kept = static_cast<double>(positives);
  out.negatives_kept = static_cast<double>(negatives);
  std::mt19937_64 rng(params.forest.seed * 0x9E3779B97F4A7C15ULL + frame_index);
  const EdgeChannels channels = ComputeEdgeChannels(frame.image, params.channels);
  const PixelFeatureExtractor extractor(channels);
  const int cols = channels.cols();
  const auto add_samples = [&](std::vector<int> pool, std::size_t count, float target) {
    for (const int index : SampleWithoutReplacement(std::move(pool), count, rng)) {
      cv::Mat1f row(1, num_features);
      extractor.Extract(index / cols, index % cols, row.ptr<float>(0));
      out.features.push_back(row);
      out.targets.push_back(target);
    }
  };
  add_samples(std::move(positive_cells), positives, 1.f);
  add_samples(std::move(negative_cells), negatives, 0.f);
  return out;
}

void AppendEdgeSamples(EdgeSamples& into, const EdgeSamples& more) {
  if (more.targets.empty()) return;
  if (into.features.empty()) into.features.create(0, more.features.cols);
  into.features.push_back(more.features);
  into.targets.insert(into.targets.end(), more.targets.begin(), more.targets.end());
  into.positive_cells += more.positive_cells;
  into.negative_cells += more.negative_cells;
  into.positives_kept += more.positives_kept;
  into.negatives_kept += more.negatives_kept;
}

Result<PixelEdgeClassifier> PixelEdgeClassifier::TrainOnSamples(const EdgeSamples& samples,
                                                                const PixelEdgeParams& params) {
  if (samples.targets.empty() || samples.negative_cells <= 0) {
    return Status::InvalidArgument(
        "pixel edge training: no frame has both boundary and non-boundary pixels outside void");
  }
  PixelEdgeClassifier classifier;
  Result<RandomForest> forest = RandomForest::Fit(samples.features, samples.targets, params.forest);
  if (!forest.ok()) return forest.status().WithContext("pixel edge training");
  classifier.forest_ = std::move(forest).value();
  classifier.channel_params_ = params.channels;
  // The odds factor that undoes the sampling: (share of negative cells kept) / (share of
  // boundary cells kept), over all frames.
  // Written as (P / N) * (kept negatives / kept positives) so that balanced samples give P / N
  // exactly.
  classifier.sampled_odds_scale_ = (samples.positive_cells / samples.negative_cells) *
                                   (samples.negatives_kept / samples.positives_kept);
  if (classifier.forest_.empty()) {
    return Status::Internal("pixel edge training: the forest trainer returned no trees");
  }
  return classifier;
}

Result<PixelEdgeClassifier> PixelEdgeClassifier::TryTrain(
    const std::vector<EdgeTrainingFrame>& frames, const PixelEdgeParams& params) {
  if (frames.empty()) return Status::InvalidArgument("pixel edge training: no frames");
  EdgeSamples all;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    Result<EdgeSamples> samples = ExtractEdgeSamples(frames[f], params, f);
    if (!samples.ok()) return samples.status();
    AppendEdgeSamples(all, *samples);
  }
  return TrainOnSamples(all, params);
}

cv::Mat1f PixelEdgeClassifier::Compute(const cv::Mat3b& bgr) const {
  if (bgr.empty()) return {};
  if (forest_.empty()) return cv::Mat1f::zeros(bgr.size());
  const EdgeChannels channels = ComputeEdgeChannels(bgr, channel_params_);
  cv::Mat1f cell_map(channels.rows(), channels.cols());
  const PixelFeatureExtractor extractor(channels);
  const ForestWalkOptions walk;  // one thread, every tree: the rows are already shared out below
  cv::parallel_for_(cv::Range(0, channels.rows()), [&](const cv::Range& rows) {
    cv::Mat1f row_features;
    for (int i = rows.start; i < rows.end; ++i) {
      extractor.ExtractRow(i, &row_features);
      // One batch per row: the forest walks each tree over the whole row (cache-friendly).
      const std::vector<float> predicted = forest_.PredictBatchScreened(row_features, walk).values;
      std::copy(predicted.begin(), predicted.end(), cell_map.ptr<float>(i));
    }
  });
  // Cell (i, j) is centred on full-resolution (2j + 0.5, 2i + 0.5), which is exactly where
  // INTER_LINEAR's half-pixel convention puts it when doubling the size.
  cv::Mat1f padded_map;
  cv::resize(cell_map, padded_map, cv::Size(2 * cell_map.cols, 2 * cell_map.rows), 0, 0,
             cv::INTER_LINEAR);
  // Clamped to [0, 1] per pixel, in bands of rows (row_bands.h).
  const cv::Mat1f unclamped = padded_map(cv::Rect(0, 0, bgr.cols, bgr.rows));
  cv::Mat1f edge(bgr.size());
  ForEachRowBand(edge.rows, [&](const cv::Range& rows) {
    cv::Mat band = edge.rowRange(rows);
    cv::min(cv::max(unclamped.rowRange(rows), 0.f), 1.f, band);
  });
  return edge;
}

// The file: header (binary_io.h), u32 feature layout version, u32 channel count, u32 feature
// count, u32 image and channel smoothing radii, then the forest (random_forest_io.cc).
Status PixelEdgeClassifier::Save(BinaryWriter& out) const {
  if (forest_.empty()) {
    return Status::FailedPrecondition("pixel edge classifier: cannot save an untrained model");
  }
  out.Header(kMagic, kFormatVersion);
  out.U32(static_cast<std::uint32_t>(kPixelFeatureLayoutVersion));
  out.U32(static_cast<std::uint32_t>(kNumEdgeChannels));
  out.U32(static_cast<std::uint32_t>(NumPixelFeatures()));
  out.U32(static_cast<std::uint32_t>(std::max(channel_params_.image_smooth_radius, 0)));
  out.U32(static_cast<std::uint32_t>(std::max(channel_params_.channel_smooth_radius, 0)));
  return forest_.Save(out);
}

Result<PixelEdgeClassifier> PixelEdgeClassifier::Load(BinaryReader& in) {
  if (Status s = in.Header(kMagic, kFormatVersion, "pixel edge classifier"); !s.ok()) return s;
  const std::uint32_t layout = in.U32("the feature layout");
  const std::uint32_t channels = in.U32("the channel count");
  const std::uint32_t features = in.U32("the feature count");
  const std::uint32_t image_radius = in.U32("the image smoothing radius");
  const std::uint32_t channel_radius = in.U32("the channel smoothing radius");
  if (!in.ok()) return in.status();
  const std::string prefix = in.source() + ": pixel edge classifier ";
  if (layout != static_cast<std::uint32_t>(kPixelFeatureLayoutVersion) ||
      channels != static_cast<std::uint32_t>(kNumEdgeChannels) ||
      features != static_cast<std::uint32_t>(NumPixelFeatures())) {
    return Status::FailedPrecondition(
        prefix + "has feature layout " + std::to_string(layout) + " with " +
        std::to_string(channels) + " channels / " + std::to_string(features) +
        " features, this build uses layout " + std::to_string(kPixelFeatureLayoutVersion) +
        " with " + std::to_string(kNumEdgeChannels) + " / " + std::to_string(NumPixelFeatures()));
  }
  if (image_radius > kMaxSmoothRadius || channel_radius > kMaxSmoothRadius) {
    return in.Corrupt("pixel edge classifier smoothing radius out of range (corrupt header)");
  }
  Result<RandomForest> forest = RandomForest::Load(in);
  if (!forest.ok()) return forest.status();
  if (forest->empty() || forest->num_features() != NumPixelFeatures()) {
    return Status::FailedPrecondition(prefix + "forest has " + std::to_string(forest->num_trees()) +
                                      " trees over " + std::to_string(forest->num_features()) +
                                      " features, expected a non-empty forest over " +
                                      std::to_string(NumPixelFeatures()));
  }
  PixelEdgeClassifier classifier;
  classifier.forest_ = std::move(forest).value();
  classifier.channel_params_.image_smooth_radius = static_cast<int>(image_radius);
  classifier.channel_params_.channel_smooth_radius = static_cast<int>(channel_radius);
  return classifier;
}

}  // namespace tod
