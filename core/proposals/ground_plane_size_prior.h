// A size filter whose ranges come from a ground-plane size prior instead of per-band extremes.
//
// The authors' recipe (§4.3, SizeFilter::Derive) takes each of three centre-row bands' min / max
// box h, w and area. On 1036 training frames that is a fair range; on the 35–50 frames a team
// has, a band holds a handful of obstacles, and its range is whatever those few happened to be:
// trained on fs-laf-dev 0–34 the nearest band admitted areas 28 808–28 868 px² (one obstacle),
// and a test obstacle 1.1× wider than the widest training one in its band lost every box on a
// camera with a narrower field of view (docs/method.md#size-filter).
//
// On a flat road seen by a level camera, an object of physical size S whose image centre is d
// rows below the horizon has an image size of about S·d / camera height. So h / d, w / d and
// area / d² do not depend on where an obstacle stands: every training obstacle, whatever its
// row, says something about the sizes allowed at every row. The prior pools them:
//   1. the horizon row y_h is the row above every obstacle centre that makes log(h / (y_c − y_h))
//      least spread over the training obstacles (a scan over rows; no camera calibration);
//   2. the ratio ranges are the training obstacles' min / max of h / d, w / d and area / d²;
//   3. narrow centre-row bands over the training obstacles' centre rows then admit, per band,
//      sizes from the smallest ratio at the band's top row to the largest at its bottom row,
//      with the paper's band-1 slack of 20 px on h and w.
// The result is an ordinary SizeFilter (bands), so window admission, the frame mapping to other
// resolutions and the manifest treat it like the authors' filter.
#pragma once

#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/proposals/size_filter.h"

namespace tod {

struct GroundPlaneSizeParams {
  int num_bands = 8;           // narrow bands approximate the continuous prior
  int min_obstacles = 8;       // fewer cannot place a horizon
  double slack_pixels = 20.0;  // on h and w at both ends and on the largest area (§4.3, band 1)
};

struct GroundPlaneSizePrior {
  double horizon_y = 0;  // image row of the horizon (may be negative or fractional)
  double h_ratio_min = 0, h_ratio_max = 0;        // h / d
  double w_ratio_min = 0, w_ratio_max = 0;        // w / d
  double area_ratio_min = 0, area_ratio_max = 0;  // area / d², d = centre row − horizon_y
  int obstacles = 0;
};

// Fits the prior to the training obstacles' boxes. InvalidArgument with fewer than
// params.min_obstacles non-empty boxes or when every centre lies on one row.
Result<GroundPlaneSizePrior> FitGroundPlaneSizePrior(const std::vector<Box>& obstacle_boxes,
                                                     const GroundPlaneSizeParams& params = {});

// The bands of the prior over the training obstacles' centre rows.
SizeFilter GroundPlaneSizeFilter(const GroundPlaneSizePrior& prior,
                                 const std::vector<Box>& obstacle_boxes,
                                 const GroundPlaneSizeParams& params = {});

}  // namespace tod
