// ORDR and OBDR on a frame's proposals (§6): features, then both regressors.
#pragma once

#include <chrono>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/stage_timer.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/model_bundle.h"
#include "core/pipeline/proposal_features.h"

namespace tod {

struct RegressedProposals {
  ProposalSet proposals;
  std::vector<float> ordr;
  std::vector<float> obdr;
  // The deadline stopped the features + ORDR before the last proposals: those were dropped
  // (proposals, ordr and obdr hold only the regressed ones).
  bool truncated = false;
  std::size_t dropped = 0;
};

struct RegressionLimits {
  // Proposals are measured and scored by ORDR in objectness order, in chunks; none is started
  // once this has passed (frame_budget.h). No deadline: all are.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  int threads = 1;  // threads sharing each chunk
  // The calibrated horizon's offset on this frame (FrameGeometry::horizon.shift): the
  // ground-plane features' horizon moves with the regions.
  double horizon_shift = 0;
};

// ORDR and OBDR scores of every proposal (features computed here); OBDR only on the boxes that
// pass the fusion gate (the rest keep 0). The timer (may be null) gets "features" and
// "regression" marks; when its check stops the frame, the result is incomplete and the caller
// returns timer->stopped(). `colour`: R1's colour tables when already built for the bundle's
// feature options (FeatureOptionsForFrame), else empty.
RegressedProposals RegressProposals(const ModelBundle& bundle, const cv::Mat3b& image,
                                    const OcclusionEdges& oaocc, const MultilayerRegions& regions,
                                    ProposalSet proposals, StageTimer* timer = nullptr,
                                    const RegressionLimits& limits = {},
                                    FrameColourTables colour = {});

}  // namespace tod
