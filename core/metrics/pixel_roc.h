// Pixel-level ROC pooled over all frames (ALGORITHM.md §8.1): thresholds t = 0, 0.005, ..., 1
// (201 values), prediction P > t (strict); obstacle pixels vs road pixels, ignore excluded.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"

namespace tod {

struct RocCurve {
  std::vector<double> thresholds;  // ascending
  std::vector<double> tpr;         // per threshold
  std::vector<double> fpr;         // per threshold
};

class PixelRocAccumulator {
 public:
  // Thresholds t_i = i / (num_thresholds - 1), i = 0 .. num_thresholds - 1 (as doubles; a
  // float probability is compared after exact promotion to double). num_thresholds >= 2.
  explicit PixelRocAccumulator(int num_thresholds = 201);
  // probability in [0,1]; obstacle / road masks: nonzero (255) = member (ignore = neither).
  // O(pixels + thresholds). A frame whose masks do not match the probability map in size is an
  // error and is not counted.
  Status Add(const cv::Mat1f& probability, const cv::Mat1b& obstacle, const cv::Mat1b& road);
  RocCurve Curve() const;
  std::int64_t obstacle_pixels() const { return obstacle_total_; }
  std::int64_t road_pixels() const { return road_total_; }
  int num_thresholds() const { return num_thresholds_; }
  // The threshold with index i, exactly as used for counting.
  double Threshold(int i) const;

 private:
  // Number of thresholds strictly below p, i.e. how many of the t_i satisfy p > t_i.
  int ThresholdsBelow(float p) const;

  int num_thresholds_;
  std::vector<std::int64_t> true_positives_;   // per threshold
  std::vector<std::int64_t> false_positives_;  // per threshold
  std::int64_t obstacle_total_ = 0;
  std::int64_t road_total_ = 0;
};

// TPR at a given FPR by linear interpolation of TPR over FPR along the curve sorted by FPR.
// Points sharing one FPR collapse to their highest TPR (the ROC's upper envelope); an FPR
// outside the curve's range takes the TPR of the nearest end point. 0 for an empty curve.
double TprAtFpr(const RocCurve& curve, double fpr);

// The table's operating points: 0.005, 0.010, ..., 0.030.
const std::vector<double>& TableFprs();

}  // namespace tod
