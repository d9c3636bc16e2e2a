#include "core/metrics/component_metrics.h"

#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <string>

namespace tod {
namespace {

constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();

// 8-connected components of a binary mask: labels (0 = background) and each label's area.
struct Components {
  cv::Mat1i labels;
  std::vector<int> area;  // index = label; area[0] is the background's
  int count() const { return static_cast<int>(area.size()) - 1; }
};

Components Label(const cv::Mat1b& mask) {
  Components c;
  cv::Mat stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, c.labels, stats, centroids, 8, CV_32S);
  c.area.resize(n);
  for (int l = 0; l < n; ++l) c.area[l] = stats.at<int>(l, cv::CC_STAT_AREA);
  return c;
}

// Clears the labels of components under min_area (they become background) and renumbers the
// rest 1..n in their order; returns the kept components.
Components KeepLarge(Components c, int min_area) {
  std::vector<int> renumber(c.area.size(), 0);
  std::vector<int> kept_area = {0};
  for (std::size_t l = 1; l < c.area.size(); ++l)
    if (c.area[l] >= min_area) {
      renumber[l] = static_cast<int>(kept_area.size());
      kept_area.push_back(c.area[l]);
    }
  for (int y = 0; y < c.labels.rows; ++y) {
    int* row = c.labels[y];
    for (int x = 0; x < c.labels.cols; ++x) row[x] = renumber[row[x]];
  }
  c.area = std::move(kept_area);
  return c;
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return kUndefined;
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

}  // namespace

Result<FrameComponents> MeasureComponents(const cv::Mat1b& predicted, const cv::Mat1b& truth,
                                          const cv::Mat1b& void_mask,
                                          const ComponentMetricsParams& params) {
  if (predicted.size() != truth.size() || void_mask.size() != truth.size())
    return Status::InvalidArgument(
        "MeasureComponents: prediction, truth and void masks differ in size");
  // Ground truth: obstacle pixels in the region of interest; small components become void.
  const cv::Mat1b truth_in_roi = (truth != 0) & (void_mask == 0);
  Components all_truth = Label(truth_in_roi);
  cv::Mat1b small_truth = (all_truth.labels > 0);
  const Components gt = KeepLarge(std::move(all_truth), params.min_truth_area);
  small_truth &= (gt.labels == 0);
  // Prediction: cleared on void (and on the voided small truth), small components dropped.
  const cv::Mat1b prediction_in_roi = (predicted != 0) & (void_mask == 0) & (small_truth == 0);
  const Components pred = KeepLarge(Label(prediction_in_roi), params.min_predicted_area);

  // Pair counts |K ∩ P| for every ground-truth K and predicted P that overlap, and per predicted
  // component its pixels on any ground truth.
  const int n_gt = gt.count(), n_pred = pred.count();
  std::vector<std::vector<std::int64_t>> overlap(n_gt + 1,
                                                 std::vector<std::int64_t>(n_pred + 1, 0));
  for (int y = 0; y < gt.labels.rows; ++y) {
    const int* g = gt.labels[y];
    const int* p = pred.labels[y];
    for (int x = 0; x < gt.labels.cols; ++x)
      if (g[x] && p[x]) ++overlap[g[x]][p[x]];
  }
  FrameComponents out;
  for (int k = 1; k <= n_gt; ++k) {
    std::int64_t intersection = 0, touching_area = 0, on_other_truth = 0;
    for (int p = 1; p <= n_pred; ++p) {
      if (overlap[k][p] == 0) continue;
      intersection += overlap[k][p];
      touching_area += pred.area[p];
      for (int other = 1; other <= n_gt; ++other)
        if (other != k) on_other_truth += overlap[other][p];
    }
    // |K ∪ P(K)| = |K| + |P(K)| - |K ∩ P(K)|, less P(K)'s pixels on the other components.
    const std::int64_t union_area = gt.area[k] + touching_area - intersection - on_other_truth;
    out.siou.push_back(static_cast<double>(intersection) / static_cast<double>(union_area));
  }
  for (int p = 1; p <= n_pred; ++p) {
    std::int64_t on_truth = 0;
    for (int k = 1; k <= n_gt; ++k) on_truth += overlap[k][p];
    out.ppv.push_back(static_cast<double>(on_truth) / static_cast<double>(pred.area[p]));
  }
  return out;
}

const std::vector<double>& ComponentF1Thresholds() {
  static const std::vector<double> taus = [] {
    std::vector<double> t;
    for (int i = 0; i <= 10; ++i) t.push_back(0.25 + 0.05 * i);
    return t;
  }();
  return taus;
}

void ComponentAccumulator::Add(const FrameComponents& frame) {
  siou_.insert(siou_.end(), frame.siou.begin(), frame.siou.end());
  ppv_.insert(ppv_.end(), frame.ppv.begin(), frame.ppv.end());
}

ComponentSummary ComponentAccumulator::Summary() const {
  ComponentSummary s;
  s.truth_components = static_cast<int>(siou_.size());
  s.predicted_components = static_cast<int>(ppv_.size());
  s.mean_siou = Mean(siou_);
  s.mean_ppv = Mean(ppv_);
  // A small epsilon so that τ = 0.3 computed as 0.25 + 0.05 accepts an sIoU of exactly 0.3.
  constexpr double kEps = 1e-9;
  for (double tau : ComponentF1Thresholds()) {
    int tp = 0, fn = 0, fp = 0;
    for (double v : siou_) (v >= tau - kEps ? tp : fn) += 1;
    for (double v : ppv_) fp += v < tau - kEps;
    const int denominator = 2 * tp + fn + fp;
    s.f1.push_back(denominator > 0 ? 2.0 * tp / denominator : kUndefined);
  }
  s.mean_f1 = Mean(s.f1);
  s.f1_at_050 = s.f1[5];
  return s;
}

}  // namespace tod
