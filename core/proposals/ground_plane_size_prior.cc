#include "core/proposals/ground_plane_size_prior.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace tod {
namespace {

double CenterY(const Box& b) { return b.y + 0.5 * b.h; }

// Spread (variance) of log(h / (centre row − horizon)) over the boxes.
double LogRatioSpread(const std::vector<Box>& boxes, double horizon_y) {
  double sum = 0, sum_sq = 0;
  for (const Box& b : boxes) {
    const double v = std::log(b.h / (CenterY(b) - horizon_y));
    sum += v;
    sum_sq += v * v;
  }
  const double n = static_cast<double>(boxes.size());
  return sum_sq / n - (sum / n) * (sum / n);
}

// The horizon row: the candidate that makes the obstacles' h / d least spread. Candidates start
// at the highest obstacle top (a tiny obstacle is lower than the camera, so its top lies below the
// horizon; this also keeps d >= h / 2) and go up in half-pixel steps over four times the rows the
// obstacles span: far enough that the spread has levelled off towards var(log h).
double FitHorizon(const std::vector<Box>& boxes) {
  double highest_top = std::numeric_limits<double>::max();
  double lowest_bottom = std::numeric_limits<double>::lowest();
  for (const Box& b : boxes) {
    highest_top = std::min<double>(highest_top, b.y);
    lowest_bottom = std::max<double>(lowest_bottom, b.bottom());
  }
  const double reach = 4.0 * std::max(lowest_bottom - highest_top, 1.0);
  double best_row = highest_top;
  double best_spread = std::numeric_limits<double>::max();
  for (double row = highest_top; row >= highest_top - reach; row -= 0.5) {
    const double spread = LogRatioSpread(boxes, row);
    if (spread < best_spread) {
      best_spread = spread;
      best_row = row;
    }
  }
  return best_row;
}

}  // namespace

Result<GroundPlaneSizePrior> FitGroundPlaneSizePrior(const std::vector<Box>& obstacle_boxes,
                                                     const GroundPlaneSizeParams& params) {
  std::vector<Box> boxes;
  for (const Box& b : obstacle_boxes) {
    if (!b.empty()) boxes.push_back(b);
  }
  if (static_cast<int>(boxes.size()) < params.min_obstacles) {
    return Status::InvalidArgument("a ground-plane size prior needs at least " +
                                   std::to_string(params.min_obstacles) + " obstacles, got " +
                                   std::to_string(boxes.size()));
  }
  const auto [lowest, highest] =
      std::minmax_element(boxes.begin(), boxes.end(),
                          [](const Box& a, const Box& b) { return CenterY(a) < CenterY(b); });
  if (CenterY(*lowest) == CenterY(*highest)) {
    return Status::InvalidArgument("every obstacle centre lies on one row: no horizon to fit");
  }
  GroundPlaneSizePrior prior;
  prior.obstacles = static_cast<int>(boxes.size());
  prior.horizon_y = FitHorizon(boxes);
  prior.h_ratio_min = prior.w_ratio_min = prior.area_ratio_min = std::numeric_limits<double>::max();
  prior.h_ratio_max = prior.w_ratio_max = prior.area_ratio_max = 0;
  for (const Box& b : boxes) {
    const double d = CenterY(b) - prior.horizon_y;  // >= h / 2 > 0 by the horizon's range
    const double h = b.h / d, w = b.w / d, area = static_cast<double>(b.area()) / (d * d);
    prior.h_ratio_min = std::min(prior.h_ratio_min, h);
    prior.h_ratio_max = std::max(prior.h_ratio_max, h);
    prior.w_ratio_min = std::min(prior.w_ratio_min, w);
    prior.w_ratio_max = std::max(prior.w_ratio_max, w);
    prior.area_ratio_min = std::min(prior.area_ratio_min, area);
    prior.area_ratio_max = std::max(prior.area_ratio_max, area);
  }
  return prior;
}

SizeFilter GroundPlaneSizeFilter(const GroundPlaneSizePrior& prior,
                                 const std::vector<Box>& obstacle_boxes,
                                 const GroundPlaneSizeParams& params) {
  SizeFilter filter;
  double y_min = std::numeric_limits<double>::max(), y_max = std::numeric_limits<double>::lowest();
  for (const Box& b : obstacle_boxes) {
    if (b.empty()) continue;
    y_min = std::min(y_min, CenterY(b));
    y_max = std::max(y_max, CenterY(b));
  }
  if (y_min > y_max || params.num_bands < 1) {
    filter.enabled = false;  // nothing to derive from, as SizeFilter::Derive
    return filter;
  }
  const int n = params.num_bands;
  const double band_height = (y_max - y_min) / n;
  const double slack = params.slack_pixels;
  for (int i = 0; i < n; ++i) {
    SizeBand band;
    // The row convention of SizeFilter::Derive: open bands overlapping by one pixel, the last one
    // closed one pixel past the lowest training centre.
    band.center_y_min = y_min + i * band_height - 1.0;
    band.center_y_max = i + 1 == n ? y_max + 1.0 : y_min + (i + 1) * band_height;
    const double d_near_horizon = std::max(band.center_y_min - prior.horizon_y, 0.0);
    const double d_far_from_horizon = std::max(band.center_y_max - prior.horizon_y, 0.0);
    band.h_min = prior.h_ratio_min * d_near_horizon - slack;
    band.h_max = prior.h_ratio_max * d_far_from_horizon + slack;
    band.w_min = prior.w_ratio_min * d_near_horizon - slack;
    band.w_max = prior.w_ratio_max * d_far_from_horizon + slack;
    band.area_min = prior.area_ratio_min * d_near_horizon * d_near_horizon;
    band.area_max = prior.area_ratio_max * d_far_from_horizon * d_far_from_horizon + slack;
    filter.bands.push_back(band);
  }
  return filter;
}

}  // namespace tod
