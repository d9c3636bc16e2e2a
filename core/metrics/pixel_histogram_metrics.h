// Pixel anomaly-segmentation metrics of Fishyscapes / SegmentMeIfYouCan, next to the paper's ROC:
// average precision (AP) and the false positive rate at a true positive rate (FPR at 95 % TPR).
//
// They are computed on the map as it is served, quantised to 8 bits exactly as the service and
// `tod detect` do (cv::Mat::convertTo(CV_8U, 255): round to nearest, clamp to 0..255). With 256
// possible values, two 256-bin histograms pooled over all frames (positives: obstacle pixels,
// negatives: free space) hold everything a pixel-sorted computation would see, so the metrics are
// exact, not an approximation on a threshold grid.
//
// Thresholds: a pixel is predicted an obstacle when its value v >= t, for t = 255 down to 0; pixels
// of equal value always share one threshold (as sklearn's precision_recall_curve treats ties).
#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"

namespace tod {

// One point per distinct operating point (a threshold level holding at least one counted pixel),
// by descending level, so recall grows along the vectors.
struct PrecisionRecallCurve {
  std::vector<int> levels;  // threshold t on the 8-bit map (predict obstacle when v >= t)
  std::vector<double> precision;
  std::vector<double> recall;
};

class PixelHistogramAccumulator {
 public:
  static constexpr int kLevels = 256;

  // probability: the float map in [0,1]; positive / negative masks: nonzero (255) = member,
  // pixels in neither (void / ignored) are not counted; a pixel in both counts in both, as in
  // PixelRocAccumulator. O(pixels). A frame whose masks do not match the map in size is an error
  // and is not counted.
  Status Add(const cv::Mat1f& probability, const cv::Mat1b& positive, const cv::Mat1b& negative);

  // Step-wise average precision, sum over thresholds of (R_t - R_prev) * P_t (the definition of
  // sklearn's average_precision_score, no interpolation). NaN when there is no positive pixel.
  double Ap() const;
  // The FPR at the highest threshold whose TPR >= target_tpr (no interpolation between
  // thresholds: the operating point a user of the 8-bit map can actually set). NaN when there is
  // no positive or no negative pixel, or when no threshold reaches target_tpr (target > 1).
  double FprAtTpr(double target_tpr) const;
  // Empty when there is no positive pixel (recall undefined).
  PrecisionRecallCurve PrCurve() const;
  // The threshold level t of the best pixel F1 = 2PR / (P + R) (ties: the highest level), the
  // operating point SegmentMeIfYouCan binarises a map at for its component metrics; -1 when
  // there is no positive pixel.
  int BestF1Level() const;

  std::int64_t positive_pixels() const { return positive_total_; }
  std::int64_t negative_pixels() const { return negative_total_; }

 private:
  // Cumulative counts at one threshold level.
  struct OperatingPoint {
    int level;
    std::int64_t true_positives;
    std::int64_t false_positives;
  };
  // The distinct operating points, by descending level (levels with no counted pixel add no
  // point: they repeat the counts of the level above).
  std::vector<OperatingPoint> OperatingPoints() const;

  std::array<std::int64_t, kLevels> positive_histogram_{};
  std::array<std::int64_t, kLevels> negative_histogram_{};
  std::int64_t positive_total_ = 0;
  std::int64_t negative_total_ = 0;
};

}  // namespace tod
