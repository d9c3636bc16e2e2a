#include "core/edges/occlusion_classifier.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <opencv2/core/utility.hpp>
#include <random>
#include <string_view>
#include <utility>

#include "core/edges/occlusion_features.h"

namespace tod {
namespace {

constexpr std::string_view kMagic("TODOCCL\0", 8);
constexpr std::uint32_t kFormatVersion = 1;
// Negatives kept per positive when balancing the training pairs (§3.4 step 4).

Status ValidateMaps(const cv::Mat3b& image, const cv::Mat1f& enhanced_edge,
                    const Superpixels& superpixels, const std::string& what) {
  if (image.empty()) return Status::InvalidArgument(what + ": image is empty");
  if (enhanced_edge.size() != image.size()) {
    return Status::InvalidArgument(what + ": enhanced_edge size differs from the image size");
  }
  if (superpixels.labels.size() != image.size()) {
    return Status::InvalidArgument(what + ": superpixels.labels size differs from the image size");
  }
  // One vectorisable pass per map instead of cv::checkRange and cv::minMaxLoc (same verdicts:
  // a float is NaN or infinite exactly when its exponent bits are all ones).
  bool finite = true;
  for (int y = 0; y < enhanced_edge.rows; ++y) {
    const float* row = enhanced_edge[y];
    std::uint32_t all_ones = 0;  // non-zero once some value has an all-ones exponent
    for (int x = 0; x < enhanced_edge.cols; ++x) {
      const std::uint32_t bits = std::bit_cast<std::uint32_t>(row[x]);
      all_ones |= static_cast<std::uint32_t>((bits & 0x7f800000u) == 0x7f800000u);
    }
    if (all_ones != 0) {
      finite = false;
      break;
    }
  }
  if (!finite) {
    return Status::InvalidArgument(what + ": enhanced_edge contains NaN or infinity");
  }
  int min_label = 0;
  int max_label = 0;
  for (int y = 0; y < superpixels.labels.rows; ++y) {
    const int* row = superpixels.labels[y];
    int row_min = row[0];
    int row_max = row[0];
    for (int x = 1; x < superpixels.labels.cols; ++x) {
      row_min = std::min(row_min, row[x]);
      row_max = std::max(row_max, row[x]);
    }
    min_label = y == 0 ? row_min : std::min(min_label, row_min);
    max_label = y == 0 ? row_max : std::max(max_label, row_max);
  }
  if (min_label < 0 || max_label > superpixels.count) {
    return Status::InvalidArgument(what + ": superpixels.labels outside [0, superpixels.count=" +
                                   std::to_string(superpixels.count) + "]");
  }
  return Status::Ok();
}

// Majority ground-truth label of one superpixel and the fraction of its pixels that are void.
struct RegionTruth {
  int majority = -1;  // -1 when every pixel is void
  double void_fraction = 1.0;
};

std::vector<RegionTruth> RegionTruths(const cv::Mat1i& superpixel_labels, int count,
                                      const cv::Mat1i& truth) {
  // A superpixel covers few distinct truth labels, so a small list per region is enough.
  std::vector<std::vector<cv::Vec2i>> histograms(static_cast<size_t>(count) + 1);
  for (int y = 0; y < truth.rows; ++y) {
    const int* s = superpixel_labels[y];
    const int* t = truth[y];
    for (int x = 0; x < truth.cols; ++x) {
      if (s[x] <= 0) continue;
      std::vector<cv::Vec2i>& h = histograms[s[x]];
      auto it = std::find_if(h.begin(), h.end(), [&](const cv::Vec2i& e) { return e[0] == t[x]; });
      if (it == h.end()) {
        h.emplace_back(t[x], 1);
      } else {
        ++(*it)[1];
      }
    }
  }
  std::vector<RegionTruth> truths(histograms.size());
  for (size_t r = 1; r < histograms.size(); ++r) {
    int total = 0;
    int void_count = 0;
    int best_count = 0;
    for (const cv::Vec2i& e : histograms[r]) {
      total += e[1];
      if (e[0] < 0) {
        void_count += e[1];
      } else if (e[1] > best_count || (e[1] == best_count && e[0] < truths[r].majority)) {
        best_count = e[1];
        truths[r].majority = e[0];
      }
    }
    truths[r].void_fraction = total > 0 ? static_cast<double>(void_count) / total : 1.0;
  }
  return truths;
}

Status ValidateOcclusionParams(const OcclusionParams& params) {
  if (!(params.floor >= 0.f && params.floor <= 1.f)) {
    return Status::InvalidArgument("occlusion params.floor must be in [0,1]");
  }
  if (!(params.max_void_fraction >= 0.0 && params.max_void_fraction <= 1.0)) {
    return Status::InvalidArgument("occlusion params.max_void_fraction must be in [0,1]");
  }
  if (params.negatives_per_positive < 1 || params.negatives_per_positive > 1000) {
    return Status::InvalidArgument("occlusion params.negatives_per_positive must be in [1,1000]");
  }
  return Status::Ok();
}

// Keeps a seeded random subset of `count` rows of `rows` (row-major, kNumOcclusionFeatures wide).
void KeepRandomRows(std::vector<float>& rows, std::size_t count, std::uint64_t seed) {
  const std::size_t total = rows.size() / kNumOcclusionFeatures;
  if (count >= total) return;
  std::vector<std::size_t> order(total);
  for (std::size_t i = 0; i < total; ++i) order[i] = i;
  std::mt19937_64 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  order.resize(count);
  std::sort(order.begin(), order.end());
  std::vector<float> kept(count * kNumOcclusionFeatures);
  for (std::size_t i = 0; i < count; ++i)
    std::copy_n(rows.data() + order[i] * kNumOcclusionFeatures, kNumOcclusionFeatures,
                kept.data() + i * kNumOcclusionFeatures);
  rows.swap(kept);
}

}  // namespace

Result<OcclusionSamples> ExtractOcclusionSamples(const OcclusionTrainingFrame& frame,
                                                 const OcclusionParams& params,
                                                 std::size_t frame_index) {
  if (Status s = ValidateOcclusionParams(params); !s.ok()) return s;
  const std::string what = "occlusion training frame " + std::to_string(frame_index);
  if (Status s = ValidateMaps(frame.image, frame.enhanced_edge, frame.superpixels, what); !s.ok()) {
    return s;
  }
  if (frame.labels.size() != frame.image.size()) {
    return Status::InvalidArgument(what + ": labels size differs from the image size");
  }
  const SuperpixelPairs pairs =
      ComputeSuperpixelPairs(frame.image, frame.enhanced_edge, frame.superpixels);
  const std::vector<RegionTruth> truths =
      RegionTruths(frame.superpixels.labels, frame.superpixels.count, frame.labels);
  OcclusionSamples out;
  for (size_t p = 0; p < pairs.pairs.size(); ++p) {
    const RegionTruth& a = truths[pairs.pairs[p][0]];
    const RegionTruth& b = truths[pairs.pairs[p][1]];
    if (a.majority < 0 || b.majority < 0 || a.void_fraction > params.max_void_fraction ||
        b.void_fraction > params.max_void_fraction) {
      continue;
    }
    const float* row = pairs.features[static_cast<int>(p)];
    if (a.majority == b.majority) {
      out.negative_rows.insert(out.negative_rows.end(), row, row + kNumOcclusionFeatures);
      continue;
    }
    // An obstacle's contour is an occlusion boundary; road against background is a real but
    // non-obstacle boundary, kept at half strength (§3.4 step 4, the 0.5 option).
    const bool obstacle_side = std::max(a.majority, b.majority) >= 2;
    out.positive_rows.insert(out.positive_rows.end(), row, row + kNumOcclusionFeatures);
    out.positive_targets.push_back(obstacle_side ? 1.f : 0.5f);
  }
  // A frame keeps at most negatives_per_positive negatives per positive (at least a few hundred),
  // so that a trainer streaming a thousand frames holds samples, not every pair of every frame.
  const std::size_t available = out.negative_rows.size() / kNumOcclusionFeatures;
  const std::size_t cap = std::max<std::size_t>(
      static_cast<std::size_t>(params.negatives_per_positive) * out.positive_targets.size(), 256);
  KeepRandomRows(out.negative_rows, std::min(available, cap),
                 params.forest.seed * 0x9E3779B97F4A7C15ULL + frame_index);
  out.negatives_available = static_cast<double>(available);
  return out;
}

void AppendOcclusionSamples(OcclusionSamples& into, const OcclusionSamples& more) {
  into.positive_rows.insert(into.positive_rows.end(), more.positive_rows.begin(),
                            more.positive_rows.end());
  into.positive_targets.insert(into.positive_targets.end(), more.positive_targets.begin(),
                               more.positive_targets.end());
  into.negative_rows.insert(into.negative_rows.end(), more.negative_rows.begin(),
                            more.negative_rows.end());
  into.negatives_available += more.negatives_available;
}

Result<OcclusionClassifier> OcclusionClassifier::FitOnSamples(OcclusionSamples samples,
                                                              const OcclusionParams& params) {
  if (Status s = ValidateOcclusionParams(params); !s.ok()) return s;
  const size_t num_positive = samples.positive_targets.size();
  if (num_positive == 0) {
    return Status::InvalidArgument(
        "occlusion training: no obstacle contour among the superpixel pairs (are there obstacles "
        "in the training frames?)");
  }
  // Balance: all positives, at most negatives_per_positive negatives each (a seeded subset).
  KeepRandomRows(samples.negative_rows,
                 static_cast<std::size_t>(params.negatives_per_positive) * num_positive,
                 params.forest.seed);
  const size_t num_negative = samples.negative_rows.size() / kNumOcclusionFeatures;
  cv::Mat1f features(static_cast<int>(num_positive + num_negative), kNumOcclusionFeatures);
  std::copy(samples.positive_rows.begin(), samples.positive_rows.end(), features[0]);
  std::copy(samples.negative_rows.begin(), samples.negative_rows.end(),
            features[static_cast<int>(num_positive)]);
  std::vector<float> targets = samples.positive_targets;
  targets.resize(num_positive + num_negative, 0.f);
  Result<RandomForest> forest = RandomForest::Fit(features, targets, params.forest);
  if (!forest.ok()) {
    return Status::InvalidArgument("occlusion training: " + forest.status().message());
  }
  OcclusionClassifier classifier;
  classifier.params_ = params;
  classifier.forest_ = std::move(forest).value();
  // Every positive pair is kept, negatives at (kept / available).
  classifier.sampled_odds_scale_ =
      samples.negatives_available > 0 ? num_negative / samples.negatives_available : 1.0;
  return classifier;
}

Result<OcclusionClassifier> OcclusionClassifier::Fit(
    const std::vector<OcclusionTrainingFrame>& frames, const OcclusionParams& params) {
  OcclusionSamples all;
  for (size_t i = 0; i < frames.size(); ++i) {
    Result<OcclusionSamples> samples = ExtractOcclusionSamples(frames[i], params, i);
    if (!samples.ok()) return samples.status();
    AppendOcclusionSamples(all, *samples);
  }
  if (frames.empty()) return Status::InvalidArgument("occlusion training: no frames");
  return FitOnSamples(std::move(all), params);
}

namespace {

// The forest's probability for every pair (row of `features`), walked in kOcclusionTreePieces
// pieces of trees (OcclusionClassifier::Paint) on as many of OpenCV's threads as
// `--threads-per-request` allows; the result depends neither on the thread count nor on the
// deadline's checks unless the deadline stops the walk.
ForestWalk PairProbabilities(const RandomForest& forest, const cv::Mat1f& features,
                             const OcclusionPaintOptions& options) {
  constexpr int kPieces = OcclusionClassifier::kOcclusionTreePieces;
  ForestWalkOptions walk;
  walk.screening = options.screening;
  walk.trees_per_piece = std::max(1, (forest.num_trees() + kPieces - 1) / kPieces);
  walk.deadline = options.deadline;
  walk.threads = cv::getNumThreads();
  return forest.PredictBatchScreened(features, walk);
}

}  // namespace

Result<cv::Mat1f> OcclusionClassifier::Paint(const cv::Mat3b& image, const cv::Mat1f& enhanced_edge,
                                             const Superpixels& superpixels,
                                             const OcclusionPaintOptions& options,
                                             int* trees_walked) const {
  if (Status s = ValidateMaps(image, enhanced_edge, superpixels, "occlusion paint"); !s.ok()) {
    return s;
  }
  const SuperpixelPairs pairs = ComputeSuperpixelPairs(image, enhanced_edge, superpixels);
  std::vector<float> strength;
  if (trees_walked != nullptr) *trees_walked = 0;
  if (trained()) {
    ForestWalk walked = PairProbabilities(forest_, pairs.features, options);
    strength = std::move(walked.values);
    if (trees_walked != nullptr) *trees_walked = walked.trees;
  } else {
    // Fallback (§3.4): mean Ê along the shared boundary, rescaled to [0,1] per image.
    strength.resize(pairs.pairs.size());
    float max_strength = 0.f;
    for (size_t p = 0; p < strength.size(); ++p) {
      strength[p] = pairs.features(static_cast<int>(p), kEdgeMean);
      max_strength = std::max(max_strength, strength[p]);
    }
    if (max_strength > 0.f) {
      for (float& v : strength) v /= max_strength;
    }
  }

  const float floor = params_.floor;
  // One pass: floor on label 0, 0 elsewhere (the former zero fill, `labels == 0` mask and
  // masked setTo wrote the same values in three passes and a temporary mask).
  cv::Mat1f painted(image.size());
  for (int y = 0; y < painted.rows; ++y) {
    const int* label = superpixels.labels[y];
    float* row = painted[y];
    for (int x = 0; x < painted.cols; ++x) row[x] = label[x] == 0 ? floor : 0.f;
  }
  float* const out = painted.ptr<float>(0);
  for (size_t i = 0; i < pairs.boundary_pixels.size(); ++i) {
    float value = floor;
    for (int k = pairs.pixel_offsets[i]; k < pairs.pixel_offsets[i + 1]; ++k) {
      value = std::max(value, strength[pairs.pixel_pairs[k]]);
    }
    out[pairs.boundary_pixels[i]] = value;
  }
  return painted;
}

// The file: header (binary_io.h), u32 feature count, the parameters (f32 floor, f64
// max_void_fraction, i32 num_trees, max_features, min_leaf_size, max_depth, f64 sample_fraction,
// u64 seed, i32 threads), u8 trained flag, then the forest (random_forest_io.cc) when trained.
Status OcclusionClassifier::Save(BinaryWriter& out) const {
  out.Header(kMagic, kFormatVersion);
  out.U32(static_cast<std::uint32_t>(kNumOcclusionFeatures));
  out.F32(params_.floor);
  out.F64(params_.max_void_fraction);
  const ForestParams& f = params_.forest;
  out.I32(f.num_trees);
  out.I32(f.max_features);
  out.I32(f.min_leaf_size);
  out.I32(f.max_depth);
  out.F64(f.sample_fraction);
  out.U64(f.seed);
  out.I32(f.threads);
  out.U8(trained() ? 1 : 0);
  if (trained()) return forest_.Save(out);
  return Status::Ok();
}

Result<OcclusionClassifier> OcclusionClassifier::Load(BinaryReader& in) {
  if (Status s = in.Header(kMagic, kFormatVersion, "occlusion classifier"); !s.ok()) return s;
  OcclusionClassifier c;
  const std::uint32_t num_features = in.U32("num_features");
  c.params_.floor = in.F32("floor");
  c.params_.max_void_fraction = in.F64("max_void_fraction");
  ForestParams& f = c.params_.forest;
  f.num_trees = in.I32("forest.num_trees");
  f.max_features = in.I32("forest.max_features");
  f.min_leaf_size = in.I32("forest.min_leaf_size");
  f.max_depth = in.I32("forest.max_depth");
  f.sample_fraction = in.F64("forest.sample_fraction");
  f.seed = in.U64("forest.seed");
  f.threads = in.I32("forest.threads");
  const std::uint8_t trained = in.U8("the trained flag");
  if (!in.ok()) return in.status();  // names the field where the bytes ran out
  if (num_features != static_cast<std::uint32_t>(kNumOcclusionFeatures)) {
    return Status::FailedPrecondition(in.source() + ": occlusion classifier has " +
                                      std::to_string(num_features) + " features, expected " +
                                      std::to_string(kNumOcclusionFeatures));
  }
  if (!(c.params_.floor >= 0.f && c.params_.floor <= 1.f)) {
    return in.Corrupt("occlusion classifier floor outside [0,1]");
  }
  if (!(c.params_.max_void_fraction >= 0.0 && c.params_.max_void_fraction <= 1.0)) {
    return in.Corrupt("occlusion classifier max_void_fraction outside [0,1]");
  }
  if (trained > 1) return in.Corrupt("occlusion classifier bad trained flag");
  if (trained == 1) {
    Result<RandomForest> forest = RandomForest::Load(in);
    if (!forest.ok()) return forest.status();
    if (forest->empty() || forest->num_features() != kNumOcclusionFeatures) {
      return in.Corrupt("occlusion classifier forest has " +
                        std::to_string(forest->num_features()) + " features, expected " +
                        std::to_string(kNumOcclusionFeatures));
    }
    c.forest_ = std::move(forest).value();
  }
  return c;
}

}  // namespace tod
