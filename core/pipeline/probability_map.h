// Fusion of the two regressors and the obstacle-occupied probability map (ALGORITHM.md §6.5, §7).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/edges/sticky_superpixels.h"
#include "core/pipeline/box_isolation.h"
#include "core/pipeline/obstacle_calibration.h"

namespace tod {

struct FusionParams {
  float beta1 = 0.3f;       // weight of OBDR
  float keep_ratio = 0.5f;  // tau_beta: the top half by ORDR passes the gate
};

// Indices of the boxes that pass the gate: the top floor(keep_ratio * n) by ORDR, stable on ties.
std::vector<int> GatedByOrdr(const std::vector<float>& ordr, const FusionParams& params = {});

// F(b) = ORDR(b) + beta1 * OBDR(b) for the top floor(keep_ratio * n) boxes by ORDR (stable
// order on ties), 0 for the rest.
std::vector<float> FuseScores(const std::vector<float>& ordr, const std::vector<float>& obdr,
                              const FusionParams& params = {});

struct ProbabilityMapParams {
  float min_score = 0.25f;  // boxes at or below are dropped (authors' code)
  float nms_iou = 0.7f;
  int max_boxes = 1000;
  float top_fraction = 0.5f;  // the top half of the kept boxes is accumulated
  // Each accumulated box's score times its isolation weight (box_isolation.h); exponent 0, the
  // default and the paper's map, leaves the scores as they are. `tod train` fits the exponent.
  BoxIsolationParams isolation;
  // Each accumulated box adds its score to a pixel times the share of the pixel's sticky
  // superpixel that the box holds (superpixel_share.h), as the calibrated map weighs it, so the
  // road in a box's corners, whose superpixels run on past the box, gains little. false, the
  // default and the paper's map, paints whole boxes; `tod train` turns it on
  // (TrainingDefaultParams; docs/method.md#superpixel-shares).
  bool superpixel_shares = false;
};

// The frame's sticky superpixels, for maps that weigh boxes by superpixel shares: the labels of
// the crop whose top-left corner is at (crop.x, crop.y), R1 (OcclusionEdges). Pixels outside the
// crop have no superpixel and take a box's whole score.
struct MapSuperpixels {
  Superpixels superpixels;  // shares the labels' buffer with the frame's (cv::Mat)
  Box crop;
};

// Score-sorted boxes with score > min_score (before NMS): the ranked list used for instance
// recall of the regressed variants.
std::vector<ScoredBox> RankedAboveThreshold(const std::vector<ScoredBox>& boxes, float min_score);

// §7 steps 2-4: the boxes the map accumulates (score > min_score, NMS, the top fraction), by
// descending score.
std::vector<ScoredBox> MapBoxes(const std::vector<ScoredBox>& boxes,
                                const ProbabilityMapParams& params = {});

// The largest score of the map's boxes that overlap `component` (its bounding box): an
// obstacle's evidence before the map is normalised (obstacle_calibration.h).
float ObstacleEvidence(const Box& component, const std::vector<ScoredBox>& map_boxes);

// The boxes a frame's map accumulates, found once per frame and shared by the maps painted from
// them and by the obstacles' evidence: `boxes` are §7 steps 2-4 (MapBoxes) with their fused
// scores, `weighted` the same boxes with what each adds to the map, its score times its
// isolation weight among the frame's boxes (box_isolation.h; the score itself at exponent 0).
struct MapAccumulation {
  std::vector<ScoredBox> boxes;
  std::vector<ScoredBox> weighted;
};
// MapBoxes of `boxes`, weighed by their isolation among `boxes`.
MapAccumulation AccumulatedBoxes(const std::vector<ScoredBox>& boxes,
                                 const ProbabilityMapParams& params);
// `map_boxes` (MapBoxes of `frame_boxes`) weighed by their isolation among `frame_boxes` under
// `isolation`: a caller that tries several weights finds the map's boxes once.
MapAccumulation WeighMapBoxes(std::vector<ScoredBox> map_boxes,
                              const std::vector<ScoredBox>& frame_boxes,
                              const BoxIsolationParams& isolation);

// §7 step 4-5 on accumulated boxes: each weighted box adds its score per pixel (difference image
// + prefix sums, so the cost is linear in boxes plus pixels), or with `superpixel_shares` its
// score times the superpixel share of each pixel (two passes over the boxes' pixels), which
// needs the frame's `superpixels` (InvalidArgument without them); then divided by the maximum.
Result<cv::Mat1f> PaintProbabilityMap(const MapAccumulation& accumulated, cv::Size image_size,
                                      bool superpixel_shares,
                                      const MapSuperpixels* superpixels = nullptr);

// §7 steps 2-5 in one call: AccumulatedBoxes, then PaintProbabilityMap with params' shares.
Result<cv::Mat1f> AccumulateProbabilityMap(const std::vector<ScoredBox>& boxes, cv::Size image_size,
                                           const ProbabilityMapParams& params = {},
                                           const MapSuperpixels* superpixels = nullptr);

// The calibrated map (not in the paper): each pixel p holds the largest, over every box b with
// F > 0 (every box the ORDR gate passed) that covers p, of CalibratedScore(F(b)) · share(p, b),
// the share of p's superpixel that b holds (superpixel_share.h): P(b frames an obstacle) times
// P(p belongs to what b frames). Unlike the paper's map it is not divided by a per-frame maximum,
// so its values mean the same on every frame (an empty road stays low); it is not a sum, so the
// road around a strong box is not raised further by the weaker boxes around it; and the road in a
// box's corners, whose superpixels run on past the box, stays low. `superpixels` label the crop
// at `crop` (R1, OcclusionEdges); pixels outside it take the box's score. Cost: twice the gated
// boxes' areas. Refuses a calibration that was not fitted: its scores would not be probabilities.
// Ok when CalibratedProbabilityMap can be made with `calibration`; else the FailedPrecondition
// it returns (a caller checks this before spending work on a frame).
Status CalibratedMapAvailable(const ObstacleCalibration& calibration);
Result<cv::Mat1f> CalibratedProbabilityMap(const std::vector<ScoredBox>& fused_boxes,
                                           cv::Size image_size,
                                           const ObstacleCalibration& calibration,
                                           const Superpixels& superpixels, const Box& crop);

struct ObstacleComponent {
  Box box;
  long long area = 0;
  float peak = 0.f;
  float mean = 0.f;
};

// Connected components (8-connected) of P > threshold, largest peak first.
std::vector<ObstacleComponent> ThresholdObstacles(const cv::Mat1f& probability, float threshold);

}  // namespace tod
