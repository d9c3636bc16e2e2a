// Training obstacles' own boxes as proposals (ours; docs/method.md#truth-box-positives):
// the box a perfect proposal stage would give, scored as the window scan scores a window, so the
// regressors can learn what a box that frames an obstacle exactly looks like even where the
// proposal stage found none.
#pragma once

#include <vector>

#include "core/base/types.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/multilayer_regions.h"
#include "core/proposals/edge_box_scorer.h"

namespace tod {

// Every obstacle's tight box, once for each region (regions ∩ R1) that holds it whole, with that
// region's Edge Boxes score of the box: ScoreSingleBox on the region's map divided by its
// maximum, with the region's window parameters (RegionBoxParams). A box no region holds whole is
// left out. In region order, then obstacle order; layer_scale is left empty.
ProposalSet TruthBoxes(const std::vector<ObstacleInstance>& obstacles, const OcclusionEdges& oaocc,
                       const MultilayerRegions& regions, const EdgeBoxParams& box_params,
                       bool multistride);

}  // namespace tod
