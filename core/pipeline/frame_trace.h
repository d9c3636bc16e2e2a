// What one ObstacleDetector::Detect call computed on its way to the detection, handed to the
// callers that look inside the pipeline: `tod eval` (the detector's own variant and the paper's
// other variants built on its edges), `tod bench` (work counters, the Edge Boxes yardstick on E),
// `tod detect --stages` (the pictures), `tod analyse` (where obstacles are lost) and training
// (the maps' superpixels for the isolation fit). The stages are composed once, in Detect; a
// trace only keeps what Detect holds anyway, so asking for it costs no stage a second time.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/probability_map.h"
#include "core/pipeline/proposal_regression.h"

namespace tod {

struct FrameTrace {
  FrameGeometry geometry;  // the bundle's regions and size filter for this frame's size
  OcclusionEdges oaocc;    // E, Ê, superpixels and the occlusion map on R1
  // Every region's boxes and scan counters, before the cross-region merge.
  FrameRegionProposals regions;
  // The merged proposals (regressed.proposals, with their layer_scale), ORDR and OBDR.
  RegressedProposals regressed;
  std::vector<ScoredBox> fused;  // regressed.proposals' boxes with their fused score F
  MapAccumulation accumulated;   // the boxes the map sums (MapAccumulation::boxes)
  cv::Mat1f served;              // the map the detection serves (DetectOptions::map_kind)
  // The map whose components are the obstacles (ObstacleComponentsMap): `served` itself unless
  // ObstaclesFromWholeBoxMap.
  cv::Mat1f components;

  MapSuperpixels map_superpixels() const { return {oaocc.superpixels, oaocc.r1}; }
};

}  // namespace tod
