// A calibrated score for each reported obstacle. The probability map is divided by its maximum
// (§7), so it always has a peak of 1 and every frame would report an obstacle at threshold 0.5;
// on a real drive most frames have none. An obstacle's evidence is instead the largest fused
// score F (before any normalisation) of the map's boxes that overlap it, and Platt scaling,
// fitted by `tod train` on the training frames, turns that into the probability that the
// component covers a real obstacle. An empty road then reports nothing.
#pragma once

#include <vector>

#include "core/base/status.h"

namespace tod {

struct ObstacleCalibration {
  bool fitted = false;  // false: score = evidence (bundles made before the calibration)
  double slope = 0.0;   // score = 1 / (1 + exp(-(slope * evidence + intercept)))
  double intercept = 0.0;
  int samples = 0;    // components it was fitted on
  int positives = 0;  // of which covered a ground-truth obstacle
  // True when the training components' evidence did not rank obstacles above the rest (the
  // unconstrained fit's slope was negative): the fit is then held monotone at slope 0, so every
  // obstacle scores the training frames' smoothed share of components on obstacles.
  bool flat = false;
};

// The calibrated score of an obstacle with the given evidence.
double CalibratedScore(const ObstacleCalibration& calibration, double evidence);

// Platt scaling: logistic regression of label on evidence by Newton's method, with Platt's
// smoothed targets (N+ + 1) / (N+ + 2) and 1 / (N- + 2) so that a perfectly separated training
// set does not drive the slope to infinity. Needs at least one positive and one negative.
// The score must not fall as the evidence rises, so the slope is constrained to be >= 0: when
// the unconstrained optimum is negative (few or unrepresentative training frames; seen on three
// of eight 20-frame dev trainings), the constrained optimum is slope 0 and the intercept the
// log-odds of the mean target (the log-likelihood is concave), reported as `flat`.
Result<ObstacleCalibration> FitObstacleCalibration(const std::vector<double>& evidence,
                                                   const std::vector<int>& labels);

}  // namespace tod
