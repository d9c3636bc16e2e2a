#include "core/pipeline/obstacle_calibration.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace tod {

double CalibratedScore(const ObstacleCalibration& calibration, double evidence) {
  if (!calibration.fitted) return evidence;
  return 1.0 / (1.0 + std::exp(-(calibration.slope * evidence + calibration.intercept)));
}

Result<ObstacleCalibration> FitObstacleCalibration(const std::vector<double>& evidence,
                                                   const std::vector<int>& labels) {
  if (evidence.size() != labels.size())
    return Status::InvalidArgument("obstacle calibration: evidence and labels differ in length");
  const int positives = static_cast<int>(std::count(labels.begin(), labels.end(), 1));
  const int negatives = static_cast<int>(labels.size()) - positives;
  if (positives == 0 || negatives == 0) {
    return Status::FailedPrecondition(
        "obstacle calibration: needs components on and off obstacles in the training frames, got " +
        std::to_string(positives) + " on and " + std::to_string(negatives) + " off");
  }
  const double hi = (positives + 1.0) / (positives + 2.0);
  const double lo = 1.0 / (negatives + 2.0);
  double a = 0.0, b = std::log((positives + 1.0) / (negatives + 1.0));
  for (int iteration = 0; iteration < 100; ++iteration) {
    // Gradient and Hessian of the cross-entropy in (a, b), plus a tiny ridge for stability.
    double ga = 0, gb = 0, haa = 1e-9, hab = 0, hbb = 1e-9;
    for (std::size_t i = 0; i < evidence.size(); ++i) {
      const double x = evidence[i];
      const double p = 1.0 / (1.0 + std::exp(-(a * x + b)));
      const double t = labels[i] == 1 ? hi : lo;
      const double w = p * (1.0 - p);
      ga += (p - t) * x, gb += (p - t);
      haa += w * x * x, hab += w * x, hbb += w;
    }
    const double det = haa * hbb - hab * hab;
    if (!(det > 0)) break;
    const double da = (hbb * ga - hab * gb) / det;
    const double db = (haa * gb - hab * ga) / det;
    a -= da, b -= db;
    if (std::abs(da) < 1e-10 && std::abs(db) < 1e-10) break;
  }
  if (!std::isfinite(a) || !std::isfinite(b))
    return Status::Internal("obstacle calibration: the fit diverged");
  ObstacleCalibration fit{.fitted = true,
                          .slope = a,
                          .intercept = b,
                          .samples = static_cast<int>(labels.size()),
                          .positives = positives};
  if (a < 0.0) {
    const double mean_target =
        (positives * hi + negatives * lo) / static_cast<double>(positives + negatives);
    fit.slope = 0.0;
    fit.intercept = std::log(mean_target / (1.0 - mean_target));
    fit.flat = true;
  }
  return fit;
}

}  // namespace tod
