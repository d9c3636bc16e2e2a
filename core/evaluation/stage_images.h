// `tod detect --stages`: the intermediate results of one frame as pictures and counts, so that a
// person can see at which stage an obstacle is lost. They are drawn from the detection's own
// FrameTrace (ObstacleDetector::Detect with a trace), so they show exactly what the detection was
// made from, at the cost of the drawing alone.
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/frame_trace.h"

namespace tod {

struct StageImageOptions {
  int proposals_drawn = 200;    // per region, the best by objectness (after the size filter)
  double edge_threshold = 0.1;  // a pixel above this counts as an edge pixel in the counts
};

struct StageImage {
  std::string name;  // file STEM_stage_<name>.png
  cv::Mat pixels;    // 8-bit, frame size
};

// Every picture has the frame's size and coordinates (maps computed on the R1 crop are placed
// into a full-frame canvas, 0 outside R1), so the pictures, the input frame and the boxes of
// STEM.json line up pixel for pixel. In writing order:
//   base_edges      E, grey, 255 = 1.0
//   enhanced_edges  Ê = n(p)·E(p), grey, 255 = K (the number of layers)
//   superpixels     the frame at half brightness, superpixel boundaries in yellow
//   occlusion       the occlusion edge map as painted (before the per-region normalisation),
//                   [0,1] -> 0..255 through the inferno colour map (black 0, yellow 1)
//   regions         the frame with R1..RK drawn and labelled
//   proposals_R1 .. proposals_RK
//                   the frame (dimmed) with region k's best proposals, red = best, yellow =
//                   worst shown, and the region's rectangle
struct StageImages {
  std::vector<StageImage> images;
  // {"width","height","layers","edge_threshold","r1":{x,y,w,h},
  //  "base_edge_pixels" (E > threshold), "enhanced_edge_pixels" (Ê > threshold),
  //  "superpixels", "occlusion_edge_pixels" (> threshold),
  //  "regions":[{"name","x","y","w","h","edge_pixels","edge_groups","windows_scored",
  //              "windows_nonzero","windows_refined","boxes_after_nms",
  //              "proposals_kept","proposals_drawn"}],
  //  "proposals_total"}; `tod detect` adds "image", the input's path.
  // Per region, edge_pixels / edge_groups describe its occlusion map normalised to max 1 as the
  // scorer sees it (pixels > EdgeBoxParams::edge_min_mag), windows_* are the
  // scorer's EdgeBoxStats, boxes_after_nms counts its output before the size filter's final
  // pass and proposals_kept after it. proposals_total is what the detector regresses.
  nlohmann::json counts;
};

// `trace` is what ObstacleDetector::Detect filled for `bgr`.
Result<StageImages> RenderStageImages(const FrameTrace& trace, const cv::Mat3b& bgr,
                                      const StageImageOptions& options = {});

// Writes base_path + "_stage_<name>.png" for each picture and base_path + "_stages.json", each
// atomically.
Status WriteStageImages(const StageImages& stages, const std::string& base_path);

}  // namespace tod
