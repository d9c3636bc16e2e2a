// Occlusion classifier (ALGORITHM.md §3.4 steps 4-5): one sample per pair of adjacent
// superpixels, features of the pair and its shared boundary, a random forest trained from the
// masks; its probability is painted onto the boundary pixels as the occlusion edge map.
// The untrained fallback scores a boundary by its mean Ê, rescaled to [0,1] per image.
#pragma once

#include <chrono>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/base/binary_io.h"
#include "core/base/status.h"
#include "core/edges/occlusion_features.h"
#include "core/edges/sticky_superpixels.h"
#include "core/forest/random_forest.h"

namespace tod {

struct OcclusionParams {
  float floor = 0.01f;  // minimum painted value on a boundary pixel
  // 400 trees (was 100, then 200): the classifier's tree-to-tree variance reaches every later
  // stage through the occlusion map. Both dev folds x two seeds, 100 -> 200 trees: TPR@FPR 0.02
  // 0.754 -> 0.793, AP 0.176 -> 0.194 (docs/findings.md#occlusion-forest-size). With ground-plane
  // box features, both folds x four seeds, 200 -> 400: AR@1000 @1 / @4 / +MS 0.260 / 0.259 /
  // 0.264 -> 0.266 / 0.272 / 0.284 (the paper's order, in 5 of 8 runs instead of 1), TPR 0.802
  // -> 0.801, AP 0.211 -> 0.209, for 40-80 ms a real frame (same section).
  ForestParams forest{.num_trees = 400, .max_features = 0, .min_leaf_size = 5};
  double max_void_fraction = 0.5;  // skip training pairs with a side more void than this
  // Negative pairs kept per obstacle-contour pair (a frame keeps at least 256). The prior
  // correction undoes the ratio (sampled_odds_scale).
  int negatives_per_positive = 4;
};

// How Paint measures and walks the pairs of one frame.
struct OcclusionPaintOptions {
  // Early exit (PipelineParams::occlusion_screening; off by default): a pair whose mean over the
  // first trees is at most the bound keeps that mean (RandomForest::PredictBatchScreened).
  ForestScreening screening;
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
};

struct OcclusionTrainingFrame {
  cv::Mat3b image;          // R1 crop
  cv::Mat1f enhanced_edge;  // Ê on the crop
  Superpixels superpixels;
  cv::Mat1i labels;  // -1 ignore, 0 background, 1 road, >= 2 obstacle instance
};

// Training pairs of one or more frames (rows of kNumOcclusionFeatures floats), with the number of
// negative pairs there were before subsampling (for the prior correction).
struct OcclusionSamples {
  std::vector<float> positive_rows;
  std::vector<float> positive_targets;  // 1 obstacle contour, 0.5 road against background
  std::vector<float> negative_rows;
  double negatives_available = 0;
};
// The pairs of one frame; negatives are subsampled per frame (seeded by frame_index).
Result<OcclusionSamples> ExtractOcclusionSamples(const OcclusionTrainingFrame& frame,
                                                 const OcclusionParams& params,
                                                 std::size_t frame_index);
void AppendOcclusionSamples(OcclusionSamples& into, const OcclusionSamples& more);

class OcclusionClassifier {
 public:
  // Untrained: mean-Ê boundary strength (the §3.4 fallback; a bundle never ships one untrained).
  OcclusionClassifier() = default;
  // Trains on the frames; invalid input (a frame whose maps disagree in size, no obstacle
  // contour, bad params) is a Status naming the frame and field.
  static Result<OcclusionClassifier> Fit(const std::vector<OcclusionTrainingFrame>& frames,
                                         const OcclusionParams& params);
  // The same from samples extracted frame by frame (ExtractOcclusionSamples).
  static Result<OcclusionClassifier> FitOnSamples(OcclusionSamples samples,
                                                  const OcclusionParams& params);
  bool trained() const { return !forest_.empty(); }
  // The trained forest (empty when untrained): for tests that compare Paint with its reference.
  const RandomForest& forest() const { return forest_; }
  int num_trees() const { return forest_.num_trees(); }
  const OcclusionParams& params() const { return params_; }
  // Of the last Fit: (share of negative pairs kept) / (share of positive pairs kept), the odds
  // factor that undoes the class balancing (PriorCorrection); 1 when nothing was dropped. Not
  // stored in the file: the bundle's manifest keeps it.
  double sampled_odds_scale() const { return sampled_odds_scale_; }

  // Occlusion edge map on the crop: boundary pixels carry the max pair probability (>= floor),
  // all other pixels 0. Inputs that disagree in size or labels out of range are an error.
  // Under a deadline (the frame budget), the forest is walked a piece of trees at a time
  // (kOcclusionTreePieces pieces) and no piece after the first starts past it: a pair's
  // probability is then the mean of the trees walked, for every pair that went on alike.
  // *trees_walked (when given) says how many trees those pairs got; with all of them (the
  // deadline not reached) the map is bit-identical to the one without a deadline.
  Result<cv::Mat1f> Paint(const cv::Mat3b& image, const cv::Mat1f& enhanced_edge,
                          const Superpixels& superpixels, const OcclusionPaintOptions& options,
                          int* trees_walked = nullptr) const;
  // Trees of the forest walked between two deadline checks: 1 / kOcclusionTreePieces of them.
  static constexpr int kOcclusionTreePieces = 16;

  // The file format is in occlusion_classifier.cc; Load's errors name the reader's source.
  Status Save(BinaryWriter& out) const;
  static Result<OcclusionClassifier> Load(BinaryReader& in);

 private:
  OcclusionParams params_;
  double sampled_odds_scale_ = 1.0;
  RandomForest forest_;
};

}  // namespace tod
