// Pixel-level ROC pooled over all frames (ALGORITHM.md §8.1): thresholds t = 0, 0.005, ..., 1
// (201 values), prediction P > t (strict); obstacle pixels vs road pixels, ignore excluded.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace tod {

struct RocCurve {
  std::vector<double> thresholds;  // ascending
  std::vector<double> tpr;         // per threshold
  std::vector<double> fpr;         // per threshold
};

class PixelRocAccumulator {
 public:
  explicit PixelRocAccumulator(int num_thresholds = 201);
  // probability in [0,1]; obstacle / road masks 255 = member (ignore = neither).
  void Add(const cv::Mat1f& probability, const cv::Mat1b& obstacle, const cv::Mat1b& road);
  RocCurve Curve() const;
  std::int64_t obstacle_pixels() const { return obstacle_total_; }
  std::int64_t road_pixels() const { return road_total_; }

 private:
  int num_thresholds_;
  std::vector<std::int64_t> true_positives_;   // per threshold
  std::vector<std::int64_t> false_positives_;  // per threshold
  std::int64_t obstacle_total_ = 0;
  std::int64_t road_total_ = 0;
};

// TPR at a given FPR by linear interpolation of TPR over FPR along the curve sorted by FPR.
double TprAtFpr(const RocCurve& curve, double fpr);

// The table's operating points: 0.005, 0.010, ..., 0.030.
const std::vector<double>& TableFprs();

}  // namespace tod
