// The Detector implementation: a loaded model bundle run stage by stage on one frame.
#pragma once

#include <memory>

#include "core/pipeline/detector.h"
#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/frame_trace.h"
#include "core/pipeline/model_bundle.h"
#include "core/pipeline/proposal_regression.h"

namespace tod {

// The obstacles of a frame: components of P > obstacle_threshold, each with its evidence (the
// largest fused score of the map's boxes, MapAccumulation::boxes, over it) and calibrated score,
// those scoring below min_obstacle_score left out.
std::vector<DetectedObstacle> ScoreObstacles(const cv::Mat1f& probability,
                                             const std::vector<ScoredBox>& map_boxes,
                                             const PipelineParams& params,
                                             const DetectOptions& options);

// The map a detection serves: the paper's normalised sum (§7) of the frame's accumulated boxes,
// or the calibrated map of its fused boxes (with the superpixels of `oaocc`).
// FailedPrecondition for the calibrated map of a bundle without a fitted calibration.
Result<cv::Mat1f> ServedProbabilityMap(const std::vector<ScoredBox>& fused_boxes,
                                       const MapAccumulation& accumulated, cv::Size image_size,
                                       const OcclusionEdges& oaocc, const PipelineParams& params,
                                       MapKind kind);

// Whether a frame's obstacles come from a map of their own, the same boxes painted whole: for
// the normalised map with superpixel shares. Shares tighten a map's pixels around each object,
// but they split the boxes' area into more and smaller components, on which the obstacles'
// calibration fits lower scores (docs/findings.md#superpixel-shares): the obstacle list, and the
// calibration, stay those of the whole-box map.
bool ObstaclesFromWholeBoxMap(const PipelineParams& params, MapKind kind);

// The map whose components are a frame's obstacles: the whole-box map when
// ObstaclesFromWholeBoxMap, else `served` itself.
Result<cv::Mat1f> ObstacleComponentsMap(const MapAccumulation& accumulated, cv::Size image_size,
                                        const PipelineParams& params, MapKind kind,
                                        const cv::Mat1f& served);

class ObstacleDetector final : public Detector {
 public:
  ObstacleDetector(ModelBundle bundle, std::string name);
  Result<Detection> Detect(const cv::Mat3b& bgr, const DetectOptions& options) const override;
  // Detect, also handing back what the stages computed (frame_trace.h) in `trace` (may be null;
  // overwritten). The stages run once either way; on an error the trace holds the stages done.
  Result<Detection> Detect(const cv::Mat3b& bgr, const DetectOptions& options,
                           FrameTrace* trace) const;
  const ModelInfo& info() const override { return info_; }
  const ModelBundle& bundle() const { return bundle_; }

 private:
  // Fusion (§6), the map's boxes and the maps (§7) of frame.regressed, into `frame`.
  Status PaintMaps(cv::Size image_size, const DetectOptions& options, int threads,
                   FrameTrace& frame) const;

  ModelBundle bundle_;
  ModelInfo info_;
};

}  // namespace tod
