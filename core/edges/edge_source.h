// Base edge map E in [0,1] (ALGORITHM.md §2.1, §3.4). One interface, three sources:
//  - "gradient": untrained colour-gradient magnitude (bring-up, zero training);
//  - "pixel_forest": a pixel edge classifier trained from the training masks' boundaries (default);
//  - "sed": OpenCV's StructuredEdgeDetection with a model file the user supplies.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/base/binary_io.h"
#include "core/base/enum_names.h"
#include "core/base/status.h"
#include "core/edges/edge_channels.h"
#include "core/forest/random_forest.h"

namespace tod {

// Which base edge map a bundle uses; its names are the manifest's "edge_source" and `tod train
// --edge-source`.
enum class EdgeKind { kPixelForest, kGradient, kSed };
template <>
struct EnumNames<EdgeKind> {
  static constexpr std::array<std::pair<EdgeKind, std::string_view>, 3> kTable{{
      {EdgeKind::kPixelForest, "pixel_forest"},
      {EdgeKind::kGradient, "gradient"},
      {EdgeKind::kSed, "sed"},
  }};
};

class EdgeSource {
 public:
  virtual ~EdgeSource() = default;
  // bgr: 8-bit colour crop. Returns E with the crop's size, values in [0,1].
  virtual cv::Mat1f Compute(const cv::Mat3b& bgr) const = 0;
  virtual EdgeKind kind() const = 0;
};

struct GradientEdgeParams {
  int smooth_radius = 1;  // triangle filter radius before the gradient
  double normalise_percentile = 0.99;
};
// Triangle-smoothed LUV (edge_channels.h), gradient magnitude max over channels, divided by its
// normalise_percentile value (by the maximum when fewer pixels respond) and clipped to [0,1].
std::unique_ptr<EdgeSource> CreateGradientEdgeSource(const GradientEdgeParams& params = {});

// Fails with a message naming the file when it cannot be read (kNotFound), is not a FileStorage
// file, lacks the model fields OpenCV reads, or fails a probe run (kInvalidArgument).
// Compute() runs single-scale SED at the model's stride (no NMS), as ALGORITHM.md §2.1.
Result<std::unique_ptr<EdgeSource>> CreateSedEdgeSource(const std::string& model_path);

// Trained pixel classifier: SED-style channels (LUV, gradient magnitude, oriented gradients at
// two scales) sampled around each pixel; label = within 2 px of a ground-truth boundary.
// Channels, features and predictions live on the stride-2 grid of edge_channels.h (as SED's
// stride 2); Compute() upsamples the grid bilinearly to the crop.
struct PixelEdgeParams {
  int samples_per_frame = 4000;  // positives at most half of it
  // Negatives drawn per positive of the same frame. 1 balances the classes (ALGORITHM.md §3.4);
  // more shows the forest more of a real frame's textures, whose cells are thousands to one
  // against boundary cells. The prior correction undoes any ratio (sampled_odds_scale).
  double negatives_per_positive = 1.0;
  int boundary_radius = 2;
  // 16 trees, not SED's 8: a pixel forest has no structured output to average over a patch, so
  // its variance is all in the trees (docs/findings.md#edge-forest-size: 8 -> 16 trees lifted every
  // mean over both dev folds and two seeds; 32 lifted them further at 1.4x the frame time).
  ForestParams forest{.num_trees = 16, .max_features = 0, .min_leaf_size = 5, .max_depth = 20};
  EdgeChannelParams channels;      // stored in the model: Compute() uses the trained values
  double max_void_fraction = 0.5;  // cells whose 6x6 neighbourhood is more void are not sampled
};

struct EdgeTrainingFrame {
  cv::Mat3b image;   // crop
  cv::Mat1i labels;  // same size: -1 ignore, 0 background, 1 road, >= 2 obstacle instance
};

// Balanced training samples of the pixel edge classifier, with what was available to sample from
// (for the prior correction).
struct EdgeSamples {
  cv::Mat1f features;
  std::vector<float> targets;
  double positive_cells = 0;  // boundary cells available in the frames that gave samples
  double negative_cells = 0;
  double positives_kept = 0;  // of them, sampled
  double negatives_kept = 0;
};
// The samples of one training frame (seeded by frame_index); none when the frame has no boundary
// or no non-boundary cell outside void.
Result<EdgeSamples> ExtractEdgeSamples(const EdgeTrainingFrame& frame,
                                       const PixelEdgeParams& params, std::size_t frame_index);
void AppendEdgeSamples(EdgeSamples& into, const EdgeSamples& more);

class PixelEdgeClassifier : public EdgeSource {
 public:
  // Untrained: Compute() gives an all-zero map.
  PixelEdgeClassifier() = default;
  // Fails on an empty frame list, a frame whose labels do not match its image, or when the
  // frames hold no boundary (or no non-boundary) sample.
  static Result<PixelEdgeClassifier> TryTrain(const std::vector<EdgeTrainingFrame>& frames,
                                              const PixelEdgeParams& params);
  // The same from samples extracted frame by frame (ExtractEdgeSamples), so a trainer never has
  // to hold the frames themselves.
  static Result<PixelEdgeClassifier> TrainOnSamples(const EdgeSamples& samples,
                                                    const PixelEdgeParams& params);
  bool trained() const { return !forest_.empty(); }
  cv::Mat1f Compute(const cv::Mat3b& bgr) const override;
  EdgeKind kind() const override { return EdgeKind::kPixelForest; }
  // Of the last TryTrain: (share of negative cells sampled) / (share of boundary cells sampled),
  // the odds factor that undoes the balanced sampling (PriorCorrection). Not stored in the file.
  double sampled_odds_scale() const { return sampled_odds_scale_; }
  // The file format is in edge_source_pixel_forest.cc; Load's errors name the reader's source.
  Status Save(BinaryWriter& out) const;
  static Result<PixelEdgeClassifier> Load(BinaryReader& in);

 private:
  RandomForest forest_;
  double sampled_odds_scale_ = 1.0;
  EdgeChannelParams channel_params_;
};

}  // namespace tod
