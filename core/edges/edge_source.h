// Base edge map E in [0,1] (ALGORITHM.md §2.1, §3.4). One interface, three sources:
//  - "gradient": untrained colour-gradient magnitude (bring-up, zero training);
//  - "pixel_forest": a pixel edge classifier trained from the training masks' boundaries (default);
//  - "sed": OpenCV's StructuredEdgeDetection with a model file the user supplies.
#pragma once

#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/base/status.h"
#include "core/forest/random_forest.h"

namespace tod {

class EdgeSource {
 public:
  virtual ~EdgeSource() = default;
  // bgr: 8-bit colour crop. Returns E with the crop's size, values in [0,1].
  virtual cv::Mat1f Compute(const cv::Mat3b& bgr) const = 0;
  virtual std::string kind() const = 0;  // "gradient", "pixel_forest", "sed"
};

struct GradientEdgeParams {
  int smooth_radius = 1;        // triangle filter radius before the gradient
  double normalise_percentile = 0.99;
};
std::unique_ptr<EdgeSource> CreateGradientEdgeSource(const GradientEdgeParams& params = {});

// Fails with a message naming the file when it cannot be read.
Result<std::unique_ptr<EdgeSource>> CreateSedEdgeSource(const std::string& model_path);

// Trained pixel classifier: SED-style channels (LUV, gradient magnitude, oriented gradients at
// two scales) sampled around each pixel; label = within 2 px of a ground-truth boundary.
struct PixelEdgeParams {
  int samples_per_frame = 4000;  // balanced positives / negatives
  int boundary_radius = 2;
  ForestParams forest{.num_trees = 8, .max_features = 0, .min_leaf_size = 5, .max_depth = 20};
};

struct EdgeTrainingFrame {
  cv::Mat3b image;       // crop
  cv::Mat1i labels;      // same size: -1 ignore, 0 background, 1 road, >= 2 obstacle instance
};

class PixelEdgeClassifier : public EdgeSource {
 public:
  static PixelEdgeClassifier Train(const std::vector<EdgeTrainingFrame>& frames,
                                   const PixelEdgeParams& params);
  cv::Mat1f Compute(const cv::Mat3b& bgr) const override;
  std::string kind() const override { return "pixel_forest"; }
  Status Save(std::ostream& out) const;
  static Result<PixelEdgeClassifier> Load(std::istream& in, const std::string& what);

 private:
  RandomForest forest_;
};

}  // namespace tod
