// SegmentMeIfYouCan's component-level metrics (the obstacle track's evaluator), measured on a
// binary prediction per frame and pooled over a split:
//   - pixels outside the region of interest (void) are ignored: they are cleared from the
//     prediction and belong to no component;
//   - ground-truth components (8-connected) under `min_truth_area` pixels are made void too;
//   - predicted components (8-connected) under `min_predicted_area` pixels are dropped;
//   - sIoU of a ground-truth component K: |K ∩ P(K)| / |(K ∪ P(K)) \ A(K)|, with P(K) the union of
//     the predicted components that touch K and A(K) the pixels of the other ground-truth
//     components, so a prediction that also covers a neighbour is not counted against K;
//   - PPV of a predicted component P: |P ∩ ground truth| / |P|;
//   - F1(τ) = 2 TP / (2 TP + FN + FP): TP = ground-truth components of sIoU >= τ, FN = those below,
//     FP = predicted components of PPV < τ, counted over the split; the mean F1 is over
//     τ = 0.25, 0.30, ..., 0.75.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"

namespace tod {

struct ComponentMetricsParams {
  int min_truth_area = 10;      // smaller ground-truth components are void
  int min_predicted_area = 50;  // smaller predicted components are dropped
};

// One frame's components: sIoU per ground-truth component, PPV per predicted component.
struct FrameComponents {
  std::vector<double> siou;
  std::vector<double> ppv;
};

// predicted, truth: nonzero = obstacle; void_mask: nonzero = outside the region of interest.
// The three must have one size (else InvalidArgument).
Result<FrameComponents> MeasureComponents(const cv::Mat1b& predicted, const cv::Mat1b& truth,
                                          const cv::Mat1b& void_mask,
                                          const ComponentMetricsParams& params = {});

// The τ grid of the mean F1: 0.25, 0.30, ..., 0.75.
const std::vector<double>& ComponentF1Thresholds();

struct ComponentSummary {
  int truth_components = 0;
  int predicted_components = 0;
  double mean_siou = 0;    // NaN without ground-truth components
  double mean_ppv = 0;     // NaN without predicted components
  std::vector<double> f1;  // per ComponentF1Thresholds(); NaN when TP + FN + FP = 0
  double mean_f1 = 0;
  double f1_at_050 = 0;
};

// Pools frames; the summary is independent of the order frames were added in.
class ComponentAccumulator {
 public:
  void Add(const FrameComponents& frame);
  ComponentSummary Summary() const;

 private:
  std::vector<double> siou_;
  std::vector<double> ppv_;
};

}  // namespace tod
