#include "core/evaluation/frame_evaluation.h"

#include "core/evaluation/edge_boxes_baseline.h"
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

// The detector's own path, timed: enhanced edges, BP = OAOCC+OLP@4+MS, regression, fusion and
// the paper's map. Kept for the other variants: the edges, the multistride regions' boxes and
// the regressed BP.
struct DetectorPath {
  OcclusionEdges oaocc;
  std::vector<RegionProposals> ms_regions;
  RegressedProposals regressed;
  std::vector<ScoredBox> fusion;  // BP's boxes with their fused scores
  MapAccumulation fusion_boxes;
  cv::Mat1f fusion_map;
};

Result<DetectorPath> RunDetectorPath(const ModelBundle& bundle, const Sample& s,
                                     const FrameGeometry& geo, StageTimer& timer,
                                     FrameEvaluation& out) {
  DetectorPath path;
  Result<OcclusionEdges> computed =
      ComputeOcclusionEdges(s.image, geo.regions, *bundle.edges, &bundle.occlusion, bundle.params,
                            /*enhance=*/true, &timer);
  if (!computed.ok()) return computed.status();
  path.oaocc = std::move(computed).value();
  const SizeFilter* filter = bundle.params.size_filter ? &geo.size_filter : nullptr;
  for (int k = 0; k < geo.regions.num_layers(); ++k)
    path.ms_regions.push_back(
        ProposeRegionBoxes(path.oaocc, geo.regions, bundle.params.boxes, k, true, filter));
  ProposalSet bp = MergeRegionBoxes(path.ms_regions, bundle.params.region_merge_iou);
  timer.Mark("proposals");
  out.ranked["OAOCC+OLP@4+MS"] = RankedOnCommonScale(bp);
  path.regressed =
      RegressProposals(bundle, s.image, path.oaocc, geo.regions, std::move(bp), &timer);
  path.fusion = ScoredWith(
      path.regressed, FuseScores(path.regressed.ordr, path.regressed.obdr, bundle.params.fusion));
  path.fusion_boxes = AccumulatedBoxes(path.fusion, bundle.params.probability_map);
  const MapSuperpixels superpixels{path.oaocc.superpixels, path.oaocc.r1};
  Result<cv::Mat1f> painted =
      PaintProbabilityMap(path.fusion_boxes, s.image.size(),
                          bundle.params.probability_map.superpixel_shares, &superpixels);
  if (!painted.ok()) return painted.status();
  path.fusion_map = std::move(painted).value();
  timer.Mark("probability_map");
  return path;
}

// OAOCC+OLP@1 (R1's boxes, whose stride factor is 1 with and without MS) and OAOCC+OLP@4 (OP:
// R2..RK scored again without MS), with OP regressed by ORDR.
Result<std::vector<ScoredBox>> AddSingleStrideVariants(const ModelBundle& bundle, const Sample& s,
                                                       const FrameGeometry& geo,
                                                       const DetectorPath& path,
                                                       FrameEvaluation& out) {
  out.ranked["OAOCC+OLP@1"] = BoxesOf(path.ms_regions.front().boxes);
  const SizeFilter* filter = bundle.params.size_filter ? &geo.size_filter : nullptr;
  std::vector<RegionProposals> plain_regions = {path.ms_regions.front()};
  for (int k = 1; k < geo.regions.num_layers(); ++k)
    plain_regions.push_back(
        ProposeRegionBoxes(path.oaocc, geo.regions, bundle.params.boxes, k, false, filter));
  ProposalSet op = MergeRegionBoxes(plain_regions, bundle.params.region_merge_iou);
  out.ranked["OAOCC+OLP@4"] = RankedOnCommonScale(op);
  const RegressedProposals op_regressed =
      RegressProposals(bundle, s.image, path.oaocc, geo.regions, std::move(op));
  return ScoredWith(op_regressed, op_regressed.ordr);
}

// The regression variants' maps (and the calibrated map when the bundle has one) and their
// ranked boxes above the map's minimum score.
Status AddRegressionVariants(const ModelBundle& bundle, const Sample& s, const DetectorPath& path,
                             const std::vector<ScoredBox>& op_ordr, FrameEvaluation& out) {
  const std::vector<ScoredBox> bp_ordr = ScoredWith(path.regressed, path.regressed.ordr);
  const MapSuperpixels superpixels{path.oaocc.superpixels, path.oaocc.r1};
  Result<cv::Mat1f> bp_ordr_map = AccumulateProbabilityMap(
      bp_ordr, s.image.size(), bundle.params.probability_map, &superpixels);
  Result<cv::Mat1f> op_ordr_map = AccumulateProbabilityMap(
      op_ordr, s.image.size(), bundle.params.probability_map, &superpixels);
  if (!bp_ordr_map.ok()) return bp_ordr_map.status();
  if (!op_ordr_map.ok()) return op_ordr_map.status();
  out.maps.emplace_back("OP+ORDR@4", std::move(op_ordr_map).value());
  out.maps.emplace_back("BP+ORDR@4", std::move(bp_ordr_map).value());
  out.maps.emplace_back("BP+Fusion@4", path.fusion_map);
  if (bundle.params.obstacle_calibration.fitted) {
    Result<cv::Mat1f> calibrated =
        ServedProbabilityMap(path.fusion, path.fusion_boxes, s.image.size(), path.oaocc,
                             bundle.params, MapKind::kCalibrated);
    if (!calibrated.ok()) return calibrated.status();
    out.maps.emplace_back(kCalibratedMapVariant, std::move(calibrated).value());
  }
  const float min_score = bundle.params.probability_map.min_score;
  out.ranked["OP+ORDR@4"] = BoxesOf(RankedAboveThreshold(op_ordr, min_score));
  out.ranked["BP+ORDR@4"] = BoxesOf(RankedAboveThreshold(bp_ordr, min_score));
  out.ranked["BP+Fusion@4"] = BoxesOf(RankedAboveThreshold(path.fusion, min_score));
  return Status::Ok();
}

// The obstacles the detector reports at its defaults (calibrated score >= 0.5), from the map it
// takes them from: false alarms (no ground-truth obstacle pixel in the box) and the ground-truth
// instances some reported box overlaps.
Status CountReportedObstacles(const ModelBundle& bundle, const Sample& s, const DetectorPath& path,
                              FrameEvaluation& out) {
  Result<cv::Mat1f> components = ObstacleComponentsMap(
      path.fusion_boxes, s.image.size(), bundle.params, MapKind::kNormalized, path.fusion_map);
  if (!components.ok()) return components.status();
  const std::vector<DetectedObstacle> reported =
      ScoreObstacles(*components, path.fusion_boxes.boxes, bundle.params, DetectOptions{});
  for (const DetectedObstacle& o : reported)
    out.false_alarms += cv::countNonZero(s.obstacle(o.box.rect())) == 0;
  for (const ObstacleInstance& inst : s.instances)
    for (const DetectedObstacle& o : reported)
      if (!Intersect(o.box, inst.box).empty()) {
        ++out.instances_found;
        break;
      }
  return Status::Ok();
}

}  // namespace

Result<FrameEvaluation> EvaluateFrame(const ModelBundle& bundle, const Sample& sample) {
  const FrameGeometry geo = GeometryForFrame(bundle, sample.image.cols, sample.image.rows);
  FrameEvaluation out;
  if (Status st = AddPlainEdgeBaselines(bundle, sample, geo, out); !st.ok()) return st;
  StageTimer timer;
  Result<DetectorPath> path = RunDetectorPath(bundle, sample, geo, timer, out);
  if (!path.ok()) return path.status();
  out.stage_times = timer.times();
  out.total_ms = timer.total_ms();
  Result<std::vector<ScoredBox>> op_ordr = AddSingleStrideVariants(bundle, sample, geo, *path, out);
  if (!op_ordr.ok()) return op_ordr.status();
  if (Status st = AddRegressionVariants(bundle, sample, *path, *op_ordr, out); !st.ok()) return st;
  if (Status st = CountReportedObstacles(bundle, sample, *path, out); !st.ok()) return st;
  return out;
}

}  // namespace tod
