#include "core/metrics/pixel_roc.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace tod {

PixelRocAccumulator::PixelRocAccumulator(int num_thresholds)
    : num_thresholds_(std::max(2, num_thresholds)),
      true_positives_(num_thresholds_, 0),
      false_positives_(num_thresholds_, 0) {}

double PixelRocAccumulator::Threshold(int i) const {
  // i / (T - 1) rather than i * step: each threshold is the double nearest the exact fraction,
  // so e.g. t_100 == 0.5 exactly and t_200 == 1.
  return static_cast<double>(i) / static_cast<double>(num_thresholds_ - 1);
}

int PixelRocAccumulator::ThresholdsBelow(float p) const {
  if (std::isnan(p)) return 0;  // NaN > t is false for every t
  const double value = p;
  // Estimate from the grid spacing, then correct against the exact thresholds so that a value
  // exactly on a threshold is never counted as above it, whatever the rounding of the estimate.
  const double estimate = std::ceil(value * (num_thresholds_ - 1));
  int below = static_cast<int>(std::clamp(estimate, 0.0, static_cast<double>(num_thresholds_)));
  while (below > 0 && !(value > Threshold(below - 1))) --below;
  while (below < num_thresholds_ && value > Threshold(below)) ++below;
  return below;
}

Status PixelRocAccumulator::Add(const cv::Mat1f& probability, const cv::Mat1b& obstacle,
                                const cv::Mat1b& road) {
  if (obstacle.size() != probability.size() || road.size() != probability.size()) {
    const auto dims = [](const cv::Mat& m) {
      return std::to_string(m.cols) + "x" + std::to_string(m.rows);
    };
    return Status::InvalidArgument("PixelRocAccumulator::Add: probability is " + dims(probability) +
                                   " but obstacle mask is " + dims(obstacle) +
                                   " and road mask is " + dims(road));
  }
  // Histograms over "number of thresholds exceeded" (0 .. T); TP(t_i) is then the count of
  // obstacle pixels exceeding more than i thresholds, a suffix sum. O(pixels + thresholds).
  std::vector<std::int64_t> obstacle_hist(num_thresholds_ + 1, 0);
  std::vector<std::int64_t> road_hist(num_thresholds_ + 1, 0);
  for (int y = 0; y < probability.rows; ++y) {
    const float* p = probability[y];
    const std::uint8_t* is_obstacle = obstacle[y];
    const std::uint8_t* is_road = road[y];
    for (int x = 0; x < probability.cols; ++x) {
      if (!is_obstacle[x] && !is_road[x]) continue;  // ignored pixel
      const int below = ThresholdsBelow(p[x]);
      if (is_obstacle[x]) ++obstacle_hist[below];
      if (is_road[x]) ++road_hist[below];
    }
  }
  std::int64_t tp = 0;
  std::int64_t fp = 0;
  for (int i = num_thresholds_ - 1; i >= 0; --i) {
    tp += obstacle_hist[i + 1];
    fp += road_hist[i + 1];
    true_positives_[i] += tp;
    false_positives_[i] += fp;
  }
  obstacle_total_ += tp + obstacle_hist[0];
  road_total_ += fp + road_hist[0];
  return Status::Ok();
}

RocCurve PixelRocAccumulator::Curve() const {
  RocCurve curve;
  curve.thresholds.resize(num_thresholds_);
  curve.tpr.resize(num_thresholds_);
  curve.fpr.resize(num_thresholds_);
  for (int i = 0; i < num_thresholds_; ++i) {
    curve.thresholds[i] = Threshold(i);
    curve.tpr[i] = obstacle_total_ > 0 ? static_cast<double>(true_positives_[i]) /
                                             static_cast<double>(obstacle_total_)
                                       : 0.0;
    curve.fpr[i] = road_total_ > 0
                       ? static_cast<double>(false_positives_[i]) / static_cast<double>(road_total_)
                       : 0.0;
  }
  return curve;
}

double TprAtFpr(const RocCurve& curve, double fpr) {
  const std::size_t n = std::min(curve.tpr.size(), curve.fpr.size());
  if (n == 0) return 0.0;
  std::vector<std::pair<double, double>> points;  // (fpr, tpr)
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) points.emplace_back(curve.fpr[i], curve.tpr[i]);
  std::sort(points.begin(), points.end());
  // Collapse equal FPRs to the highest TPR (sorted ascending, so the last of each run).
  std::vector<std::pair<double, double>> envelope;
  for (const auto& point : points) {
    if (!envelope.empty() && envelope.back().first == point.first) {
      envelope.back().second = point.second;
    } else {
      envelope.push_back(point);
    }
  }
  if (std::isnan(fpr)) return std::nan("");
  if (fpr <= envelope.front().first) return envelope.front().second;
  if (fpr >= envelope.back().first) return envelope.back().second;
  const auto upper = std::upper_bound(
      envelope.begin(), envelope.end(), fpr,
      [](double value, const std::pair<double, double>& point) { return value < point.first; });
  const auto lower = upper - 1;
  const double fraction = (fpr - lower->first) / (upper->first - lower->first);
  return lower->second + fraction * (upper->second - lower->second);
}

const std::vector<double>& TableFprs() {
  static const std::vector<double> fprs = {0.005, 0.010, 0.015, 0.020, 0.025, 0.030};
  return fprs;
}

}  // namespace tod
