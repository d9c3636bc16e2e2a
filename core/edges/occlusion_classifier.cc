#include "core/edges/occlusion_classifier.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <random>
#include <utility>

#include "core/edges/occlusion_features.h"

namespace tod {
namespace {

constexpr char kMagic[8] = {'T', 'O', 'D', 'O', 'C', 'C', 'L', '\0'};
constexpr std::uint32_t kFormatVersion = 1;
// Negatives kept per positive when balancing the training pairs (§3.4 step 4).
constexpr size_t kNegativesPerPositive = 4;

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

template <typename T>
void WriteValue(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
Status ReadValue(std::istream& in, T& value, const std::string& what, const char* field) {
  if (!in.read(reinterpret_cast<char*>(&value), sizeof(T))) {
    return Status::DataLoss(what + ": occlusion classifier truncated while reading " + field);
  }
  return Status::Ok();
}

}  // namespace

Result<OcclusionClassifier> OcclusionClassifier::Fit(
    const std::vector<OcclusionTrainingFrame>& frames, const OcclusionParams& params) {
  if (!(params.floor >= 0.f && params.floor <= 1.f)) {
    return Status::InvalidArgument("occlusion params.floor must be in [0,1]");
  }
  if (!(params.max_void_fraction >= 0.0 && params.max_void_fraction <= 1.0)) {
    return Status::InvalidArgument("occlusion params.max_void_fraction must be in [0,1]");
  }
  std::vector<float> positive_rows;  // flattened feature rows
  std::vector<float> positive_targets;
  std::vector<float> negative_rows;
  for (size_t i = 0; i < frames.size(); ++i) {
    const OcclusionTrainingFrame& frame = frames[i];
    const std::string what = "occlusion training frame " + std::to_string(i);
    if (Status s = ValidateMaps(frame.image, frame.enhanced_edge, frame.superpixels, what);
        !s.ok()) {
      return s;
    }
    if (frame.labels.size() != frame.image.size()) {
      return Status::InvalidArgument(what + ": labels size differs from the image size");
    }
    const SuperpixelPairs pairs =
        ComputeSuperpixelPairs(frame.image, frame.enhanced_edge, frame.superpixels);
    const std::vector<RegionTruth> truths =
        RegionTruths(frame.superpixels.labels, frame.superpixels.count, frame.labels);
    for (size_t p = 0; p < pairs.pairs.size(); ++p) {
      const RegionTruth& a = truths[pairs.pairs[p][0]];
      const RegionTruth& b = truths[pairs.pairs[p][1]];
      if (a.majority < 0 || b.majority < 0 || a.void_fraction > params.max_void_fraction ||
          b.void_fraction > params.max_void_fraction) {
        continue;
      }
      const float* row = pairs.features[static_cast<int>(p)];
      if (a.majority == b.majority) {
        negative_rows.insert(negative_rows.end(), row, row + kNumOcclusionFeatures);
        continue;
      }
      // An obstacle's contour is an occlusion boundary; road against background is a real but
      // non-obstacle boundary, kept at half strength (§3.4 step 4, the 0.5 option).
      const bool obstacle_side = std::max(a.majority, b.majority) >= 2;
      positive_rows.insert(positive_rows.end(), row, row + kNumOcclusionFeatures);
      positive_targets.push_back(obstacle_side ? 1.f : 0.5f);
    }
  }
  const size_t num_positive = positive_targets.size();
  size_t num_negative = negative_rows.size() / kNumOcclusionFeatures;
  if (num_positive + num_negative == 0) {
    return Status::InvalidArgument("occlusion training: no usable superpixel pair in " +
                                   std::to_string(frames.size()) + " frames");
  }
  // Balance: all positives, at most kNegativesPerPositive negatives each (a seeded subset).
  std::vector<size_t> negative_order(num_negative);
  for (size_t i = 0; i < num_negative; ++i) negative_order[i] = i;
  const size_t keep_negative = num_positive == 0
                                   ? num_negative
                                   : std::min(num_negative, kNegativesPerPositive * num_positive);
  if (keep_negative < num_negative) {
    std::mt19937_64 rng(params.forest.seed);
    std::shuffle(negative_order.begin(), negative_order.end(), rng);
    negative_order.resize(keep_negative);
    std::sort(negative_order.begin(), negative_order.end());
  }
  const double negative_share_kept =
      num_negative > 0 ? static_cast<double>(negative_order.size()) / num_negative : 1.0;
  num_negative = negative_order.size();
  cv::Mat1f features(static_cast<int>(num_positive + num_negative), kNumOcclusionFeatures);
  std::vector<float> targets;
  targets.reserve(num_positive + num_negative);
  for (size_t i = 0; i < num_positive; ++i) {
    std::copy_n(positive_rows.data() + i * kNumOcclusionFeatures, kNumOcclusionFeatures,
                features[static_cast<int>(i)]);
    targets.push_back(positive_targets[i]);
  }
  for (size_t i = 0; i < num_negative; ++i) {
    std::copy_n(negative_rows.data() + negative_order[i] * kNumOcclusionFeatures,
                kNumOcclusionFeatures, features[static_cast<int>(num_positive + i)]);
    targets.push_back(0.f);
  }
  Result<RandomForest> forest = RandomForest::Fit(features, targets, params.forest);
  if (!forest.ok()) {
    return Status::InvalidArgument("occlusion training: " + forest.status().message());
  }
  OcclusionClassifier classifier;
  classifier.params_ = params;
  classifier.forest_ = std::move(forest).value();
  classifier.sampled_odds_scale_ = negative_share_kept;  // every positive pair is kept
  return classifier;
}

OcclusionClassifier OcclusionClassifier::Train(const std::vector<OcclusionTrainingFrame>& frames,
                                               const OcclusionParams& params) {
  Result<OcclusionClassifier> result = Fit(frames, params);
  if (!result.ok()) {
    OcclusionClassifier untrained;
    untrained.params_ = params;
    return untrained;
  }
  return std::move(result).value();
}

Result<cv::Mat1f> OcclusionClassifier::PaintChecked(const cv::Mat3b& image,
                                                    const cv::Mat1f& enhanced_edge,
                                                    const Superpixels& superpixels) const {
  if (Status s = ValidateMaps(image, enhanced_edge, superpixels, "occlusion paint"); !s.ok()) {
    return s;
  }
  const SuperpixelPairs pairs = ComputeSuperpixelPairs(image, enhanced_edge, superpixels);
  std::vector<float> strength;
  if (trained()) {
    strength = forest_.PredictBatch(pairs.features);
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

cv::Mat1f OcclusionClassifier::Paint(const cv::Mat3b& image, const cv::Mat1f& enhanced_edge,
                                     const Superpixels& superpixels) const {
  Result<cv::Mat1f> painted = PaintChecked(image, enhanced_edge, superpixels);
  if (!painted.ok()) return cv::Mat1f();
  return std::move(painted).value();
}

Status OcclusionClassifier::Save(std::ostream& out) const {
  out.write(kMagic, sizeof(kMagic));
  WriteValue(out, kFormatVersion);
  WriteValue(out, static_cast<std::uint32_t>(kNumOcclusionFeatures));
  WriteValue(out, params_.floor);
  WriteValue(out, params_.max_void_fraction);
  const ForestParams& f = params_.forest;
  WriteValue(out, static_cast<std::int32_t>(f.num_trees));
  WriteValue(out, static_cast<std::int32_t>(f.max_features));
  WriteValue(out, static_cast<std::int32_t>(f.min_leaf_size));
  WriteValue(out, static_cast<std::int32_t>(f.max_depth));
  WriteValue(out, f.sample_fraction);
  WriteValue(out, f.seed);
  WriteValue(out, static_cast<std::int32_t>(f.threads));
  WriteValue(out, static_cast<std::uint8_t>(trained() ? 1 : 0));
  if (!out) return Status::Internal("occlusion classifier: write failed");
  if (trained()) return forest_.Save(out);
  return Status::Ok();
}

Result<OcclusionClassifier> OcclusionClassifier::Load(std::istream& in, const std::string& what) {
  char magic[sizeof(kMagic)];
  if (!in.read(magic, sizeof(magic))) {
    return Status::DataLoss(what + ": occlusion classifier truncated while reading magic");
  }
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) {
    return Status::InvalidArgument(what + ": not an occlusion classifier (bad magic)");
  }
  std::uint32_t version = 0;
  std::uint32_t num_features = 0;
  OcclusionClassifier c;
  std::int32_t num_trees = 0;
  std::int32_t max_features = 0;
  std::int32_t min_leaf = 0;
  std::int32_t max_depth = 0;
  std::int32_t threads = 0;
  std::uint8_t trained = 0;
  if (Status s = ReadValue(in, version, what, "version"); !s.ok()) return s;
  if (version != kFormatVersion) {
    return Status::FailedPrecondition(what + ": occlusion classifier format version " +
                                      std::to_string(version) + ", expected " +
                                      std::to_string(kFormatVersion));
  }
  ForestParams& f = c.params_.forest;
  const Status reads[] = {
      ReadValue(in, num_features, what, "num_features"),
      ReadValue(in, c.params_.floor, what, "floor"),
      ReadValue(in, c.params_.max_void_fraction, what, "max_void_fraction"),
      ReadValue(in, num_trees, what, "forest.num_trees"),
      ReadValue(in, max_features, what, "forest.max_features"),
      ReadValue(in, min_leaf, what, "forest.min_leaf_size"),
      ReadValue(in, max_depth, what, "forest.max_depth"),
      ReadValue(in, f.sample_fraction, what, "forest.sample_fraction"),
      ReadValue(in, f.seed, what, "forest.seed"),
      ReadValue(in, threads, what, "forest.threads"),
      ReadValue(in, trained, what, "trained flag"),
  };
  for (const Status& s : reads) {
    if (!s.ok()) return s;  // the first failed read names the field where the stream ended
  }
  f.num_trees = num_trees;
  f.max_features = max_features;
  f.min_leaf_size = min_leaf;
  f.max_depth = max_depth;
  f.threads = threads;
  if (num_features != static_cast<std::uint32_t>(kNumOcclusionFeatures)) {
    return Status::FailedPrecondition(what + ": occlusion classifier has " +
                                      std::to_string(num_features) + " features, expected " +
                                      std::to_string(kNumOcclusionFeatures));
  }
  if (!(c.params_.floor >= 0.f && c.params_.floor <= 1.f)) {
    return Status::DataLoss(what + ": occlusion classifier floor outside [0,1]");
  }
  if (!(c.params_.max_void_fraction >= 0.0 && c.params_.max_void_fraction <= 1.0)) {
    return Status::DataLoss(what + ": occlusion classifier max_void_fraction outside [0,1]");
  }
  if (trained > 1) return Status::DataLoss(what + ": occlusion classifier bad trained flag");
  if (trained == 1) {
    Result<RandomForest> forest = RandomForest::Load(in, what);
    if (!forest.ok()) return forest.status();
    if (forest->empty() || forest->num_features() != kNumOcclusionFeatures) {
      return Status::DataLoss(what + ": occlusion classifier forest has " +
                              std::to_string(forest->num_features()) + " features, expected " +
                              std::to_string(kNumOcclusionFeatures));
    }
    c.forest_ = std::move(forest).value();
  }
  return c;
}

}  // namespace tod
