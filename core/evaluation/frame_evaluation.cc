#include "core/evaluation/frame_evaluation.h"

#include <algorithm>

#include "core/evaluation/component_evaluation.h"
#include "core/evaluation/edge_boxes_baseline.h"
#include "core/evaluation/obstacle_list_sweep.h"
#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/probability_map.h"
#include "core/pipeline/proposal_regression.h"

namespace tod {
namespace {

std::vector<Box> BoxesOf(const std::vector<ScoredBox>& boxes) {
  std::vector<Box> out;
  out.reserve(boxes.size());
  for (const auto& b : boxes) out.push_back(b.box);
  return out;
}

// The regressed boxes with one of their scores.
std::vector<ScoredBox> ScoredWith(const RegressedProposals& regressed,
                                  const std::vector<float>& scores) {
  std::vector<ScoredBox> out(scores.size());
  for (std::size_t j = 0; j < scores.size(); ++j)
    out[j] = {regressed.proposals.boxes[j].box, scores[j]};
  return out;
}

// The proposal-only baselines on plain (not obstacle-aware) edges: EB and OLP@1. OLP@1 must not
// run the occlusion classifier, which learned its features on enhanced edges Ê: it scores each
// superpixel boundary by its mean plain E instead (the untrained boundary strength of §3.4), so
// OLP@1 -> OAOCC+OLP@1 measures enhancement plus the trained obstacle-aware classifier.
Status AddPlainEdgeBaselines(const ModelBundle& bundle, const Sample& s, const FrameGeometry& geo,
                             FrameEvaluation& out) {
  const OcclusionClassifier untrained_boundaries;
  PipelineParams plain_params = bundle.params;
  plain_params.prior_correction.occlusion_odds = 1.0;  // mean E is no classifier probability
  const Result<OcclusionEdges> computed = ComputeOcclusionEdges(
      s.image, geo.regions, *bundle.edges, &untrained_boundaries, plain_params, /*enhance=*/false);
  if (!computed.ok()) return computed.status();
  const OcclusionEdges& plain = *computed;
  out.ranked["EB"] = EdgeBoxesBaseline(plain.base_edge, plain.r1, kEvalMaxProposals);
  const ProposalSet olp1 = ProposeBoxes(
      plain, geo.regions, bundle.params.boxes,
      {1, false, bundle.params.size_filter, bundle.params.region_merge_iou}, geo.size_filter);
  out.ranked["OLP@1"] = BoxesOf(olp1.boxes);
  return Status::Ok();
}

// The detector's own path, as Detect composes it: enhanced edges, BP = OAOCC+OLP@4+MS,
// regression, fusion and the paper's map, timed stage by stage. Its trace (the edges, the
// regions' boxes, the regressed BP, the fused boxes and the map) feeds the other variants.
struct DetectorPath {
  FrameTrace trace;
  Detection detection;
};

Result<DetectorPath> RunDetectorPath(const ObstacleDetector& detector, const Sample& s,
                                     const DetectOptions& options, FrameEvaluation& out) {
  DetectorPath path;
  // The defaults `tod detect` reports obstacles at; every proposal feeds the map either way.
  Result<Detection> detected = detector.Detect(s.image, options, &path.trace);
  if (!detected.ok()) return detected.status();
  path.detection = std::move(detected).value();
  out.ranked["OAOCC+OLP@4+MS"] = RankedOnCommonScale(path.trace.regressed.proposals);
  return path;
}

// OAOCC+OLP@1 (R1's boxes, whose stride factor is 1 with and without MS) and OAOCC+OLP@4 (OP:
// R2..RK scored again without MS), with OP regressed by ORDR.
Result<std::vector<ScoredBox>> AddSingleStrideVariants(const ModelBundle& bundle, const Sample& s,
                                                       const FrameTrace& trace,
                                                       FrameEvaluation& out) {
  const std::vector<RegionProposals>& ms_regions = trace.regions.per_region;
  const FrameGeometry& geo = trace.geometry;
  out.ranked["OAOCC+OLP@1"] = BoxesOf(ms_regions.front().boxes);
  const SizeFilter* filter = bundle.params.size_filter ? &geo.size_filter : nullptr;
  std::vector<RegionProposals> plain_regions = {ms_regions.front()};
  for (int k = 1; k < geo.regions.num_layers(); ++k)
    plain_regions.push_back(
        ProposeRegionBoxes(trace.oaocc, geo.regions, bundle.params.boxes, k, false, filter));
  ProposalSet op = MergeRegionBoxes(plain_regions, bundle.params.region_merge_iou);
  out.ranked["OAOCC+OLP@4"] = RankedOnCommonScale(op);
  const RegressedProposals op_regressed =
      RegressProposals(bundle, s.image, trace.oaocc, geo.regions, std::move(op), nullptr,
                       {.horizon_shift = geo.horizon.shift});
  return ScoredWith(op_regressed, op_regressed.ordr);
}

// The regression variants' maps (and the calibrated map when the bundle has one) and their
// ranked boxes above the map's minimum score.
Status AddRegressionVariants(const ModelBundle& bundle, const Sample& s, const FrameTrace& trace,
                             const std::vector<ScoredBox>& op_ordr, FrameEvaluation& out) {
  const std::vector<ScoredBox> bp_ordr = ScoredWith(trace.regressed, trace.regressed.ordr);
  const MapSuperpixels superpixels = trace.map_superpixels();
  Result<cv::Mat1f> bp_ordr_map = AccumulateProbabilityMap(
      bp_ordr, s.image.size(), bundle.params.probability_map, &superpixels);
  Result<cv::Mat1f> op_ordr_map = AccumulateProbabilityMap(
      op_ordr, s.image.size(), bundle.params.probability_map, &superpixels);
  if (!bp_ordr_map.ok()) return bp_ordr_map.status();
  if (!op_ordr_map.ok()) return op_ordr_map.status();
  out.maps.emplace_back("OP+ORDR@4", std::move(op_ordr_map).value());
  out.maps.emplace_back("BP+ORDR@4", std::move(bp_ordr_map).value());
  out.maps.emplace_back("BP+Fusion@4", trace.served);
  if (bundle.params.obstacle_calibration.fitted) {
    Result<cv::Mat1f> calibrated =
        ServedProbabilityMap(trace.fused, trace.accumulated, s.image.size(), trace.oaocc,
                             bundle.params, MapKind::kCalibrated);
    if (!calibrated.ok()) return calibrated.status();
    out.maps.emplace_back(kCalibratedMapVariant, std::move(calibrated).value());
  }
  const float min_score = bundle.params.probability_map.min_score;
  out.ranked["OP+ORDR@4"] = BoxesOf(RankedAboveThreshold(op_ordr, min_score));
  out.ranked["BP+ORDR@4"] = BoxesOf(RankedAboveThreshold(bp_ordr, min_score));
  out.ranked["BP+Fusion@4"] = BoxesOf(RankedAboveThreshold(trace.fused, min_score));
  return Status::Ok();
}

// The obstacles the detector reports at its defaults (calibrated score >= 0.5): false alarms
// (no ground-truth obstacle pixel in the box), the ground-truth instances some reported box
// overlaps or matches at box IoU 0.25 / 0.5, and the components of the reported pixels.
Status MeasureReportedObstacles(const Sample& s, const FrameTrace& trace,
                                const std::vector<DetectedObstacle>& reported,
                                FrameEvaluation& out) {
  std::vector<Box> boxes;
  for (const DetectedObstacle& o : reported) boxes.push_back(o.box);
  out.reported = CountObstacleList(s, boxes);
  const cv::Mat1b pixels =
      ReportedObstaclePixels(trace.components, DetectOptions{}.obstacle_threshold, reported);
  Result<FrameComponents> components = MeasureComponents(pixels, s.obstacle, ComponentVoidMask(s));
  if (!components.ok()) return components.status();
  out.reported_components = std::move(components).value();
  return Status::Ok();
}

}  // namespace

Result<FrameEvaluation> EvaluateFrame(const ObstacleDetector& detector, const Sample& sample,
                                      const DetectOptions& options) {
  const ModelBundle& bundle = detector.bundle();
  FrameEvaluation out;
  Result<DetectorPath> path = RunDetectorPath(detector, sample, options, out);
  if (!path.ok()) return path.status();
  out.horizon = path->detection.horizon;
  // The baselines stand on the geometry the detector used (calibrated like it).
  if (Status st = AddPlainEdgeBaselines(bundle, sample, path->trace.geometry, out); !st.ok())
    return st;
  out.stage_times = path->detection.timings;
  out.total_ms = 0;
  for (const auto& [stage, ms] : out.stage_times) out.total_ms += ms;
  const FrameTrace& trace = path->trace;
  Result<std::vector<ScoredBox>> op_ordr = AddSingleStrideVariants(bundle, sample, trace, out);
  if (!op_ordr.ok()) return op_ordr.status();
  if (Status st = AddRegressionVariants(bundle, sample, trace, *op_ordr, out); !st.ok()) return st;
  if (Status st = MeasureReportedObstacles(sample, trace, path->detection.obstacles, out); !st.ok())
    return st;
  const auto calibrated = std::find_if(out.maps.begin(), out.maps.end(), [](const auto& m) {
    return m.first == kCalibratedMapVariant;
  });
  out.list_sweep = SweepObstacleLists(sample, trace, bundle.params,
                                      calibrated == out.maps.end() ? nullptr : &calibrated->second);
  return out;
}

}  // namespace tod
