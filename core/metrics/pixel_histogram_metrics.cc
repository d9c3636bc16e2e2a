#include "core/metrics/pixel_histogram_metrics.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace tod {
namespace {

constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();

double Ratio(std::int64_t numerator, std::int64_t denominator) {
  return static_cast<double>(numerator) / static_cast<double>(denominator);
}

}  // namespace

Status PixelHistogramAccumulator::Add(const cv::Mat1f& probability, const cv::Mat1b& positive,
                                      const cv::Mat1b& negative) {
  if (positive.size() != probability.size() || negative.size() != probability.size()) {
    const auto dims = [](const cv::Mat& m) {
      return std::to_string(m.cols) + "x" + std::to_string(m.rows);
    };
    return Status::InvalidArgument("PixelHistogramAccumulator::Add: probability is " +
                                   dims(probability) + " but positive mask is " + dims(positive) +
                                   " and negative mask is " + dims(negative));
  }
  // The very call that makes the served map (ProbabilityTo8Bit, EncodeProbabilityPng), so each
  // pixel lands in the bin of the value a client reads, ties at .5 and clamping included.
  cv::Mat1b served;
  probability.convertTo(served, CV_8U, 255.0);
  for (int y = 0; y < served.rows; ++y) {
    const std::uint8_t* value = served[y];
    const std::uint8_t* is_positive = positive[y];
    const std::uint8_t* is_negative = negative[y];
    for (int x = 0; x < served.cols; ++x) {
      if (is_positive[x]) ++positive_histogram_[value[x]];
      if (is_negative[x]) ++negative_histogram_[value[x]];
    }
  }
  positive_total_ = 0;
  negative_total_ = 0;
  for (int v = 0; v < kLevels; ++v) {
    positive_total_ += positive_histogram_[v];
    negative_total_ += negative_histogram_[v];
  }
  return Status::Ok();
}

std::vector<PixelHistogramAccumulator::OperatingPoint> PixelHistogramAccumulator::OperatingPoints()
    const {
  std::vector<OperatingPoint> points;
  std::int64_t true_positives = 0;
  std::int64_t false_positives = 0;
  for (int level = kLevels - 1; level >= 0; --level) {
    if (positive_histogram_[level] == 0 && negative_histogram_[level] == 0) continue;
    true_positives += positive_histogram_[level];
    false_positives += negative_histogram_[level];
    points.push_back({level, true_positives, false_positives});
  }
  return points;
}

double PixelHistogramAccumulator::Ap() const {
  if (positive_total_ == 0) return kUndefined;
  // Every operating point has at least one predicted pixel, so precision is always defined.
  double average_precision = 0.0;
  double previous_recall = 0.0;
  for (const OperatingPoint& point : OperatingPoints()) {
    const double recall = Ratio(point.true_positives, positive_total_);
    const double precision =
        Ratio(point.true_positives, point.true_positives + point.false_positives);
    average_precision += (recall - previous_recall) * precision;
    previous_recall = recall;
  }
  return average_precision;
}

double PixelHistogramAccumulator::FprAtTpr(double target_tpr) const {
  if (positive_total_ == 0 || negative_total_ == 0) return kUndefined;
  // TPR only grows as the threshold falls, so the first level from the top that reaches the
  // target is the highest such threshold (every level, not only the occupied ones, so that a
  // target of 0 is met at t = 255 as the definition says). TP / P rounds monotonically, so an
  // exact 0.95 (19 of 20 pixels) compares equal to the literal 0.95.
  std::int64_t true_positives = 0;
  std::int64_t false_positives = 0;
  for (int level = kLevels - 1; level >= 0; --level) {
    true_positives += positive_histogram_[level];
    false_positives += negative_histogram_[level];
    if (Ratio(true_positives, positive_total_) >= target_tpr)
      return Ratio(false_positives, negative_total_);
  }
  return kUndefined;
}

PrecisionRecallCurve PixelHistogramAccumulator::PrCurve() const {
  PrecisionRecallCurve curve;
  if (positive_total_ == 0) return curve;
  for (const OperatingPoint& point : OperatingPoints()) {
    curve.levels.push_back(point.level);
    curve.precision.push_back(
        Ratio(point.true_positives, point.true_positives + point.false_positives));
    curve.recall.push_back(Ratio(point.true_positives, positive_total_));
  }
  return curve;
}

int PixelHistogramAccumulator::BestF1Level() const {
  if (positive_total_ == 0) return -1;
  int best_level = -1;
  double best_f1 = -1.0;
  for (const OperatingPoint& point : OperatingPoints()) {
    // F1 = 2 TP / (2 TP + FP + FN), FN = P - TP.
    const double f1 = Ratio(2 * point.true_positives,
                            point.true_positives + point.false_positives + positive_total_);
    if (f1 > best_f1) {
      best_f1 = f1;
      best_level = point.level;
    }
  }
  return best_level;
}

}  // namespace tod
