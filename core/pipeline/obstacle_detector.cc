#include "core/pipeline/obstacle_detector.h"

#include <algorithm>
#include <filesystem>
#include <numeric>

#include "core/pipeline/frame_budget.h"
#include "core/pipeline/parallel.h"

namespace tod {

std::vector<DetectedObstacle> ScoreObstacles(const cv::Mat1f& probability,
                                             const std::vector<ScoredBox>& map_boxes,
                                             const PipelineParams& params,
                                             const DetectOptions& options) {
  std::vector<DetectedObstacle> out;
  for (const ObstacleComponent& c : ThresholdObstacles(probability, options.obstacle_threshold)) {
    if (c.area < options.min_obstacle_area) continue;
    const float evidence = ObstacleEvidence(c.box, map_boxes);
    const float score = static_cast<float>(CalibratedScore(params.obstacle_calibration, evidence));
    if (score < options.min_obstacle_score) continue;
    out.push_back({c.box, c.area, c.peak, c.mean, evidence, score});
  }
  return out;
}

Result<cv::Mat1f> ServedProbabilityMap(const std::vector<ScoredBox>& fused_boxes,
                                       const MapAccumulation& accumulated, cv::Size image_size,
                                       const OcclusionEdges& oaocc, const PipelineParams& params,
                                       MapKind kind) {
  if (kind == MapKind::kCalibrated)
    return CalibratedProbabilityMap(fused_boxes, image_size, params.obstacle_calibration,
                                    oaocc.superpixels, oaocc.r1);
  const MapSuperpixels superpixels{oaocc.superpixels, oaocc.r1};
  return PaintProbabilityMap(accumulated, image_size, params.probability_map.superpixel_shares,
                             &superpixels);
}

bool ObstaclesFromWholeBoxMap(const PipelineParams& params, MapKind kind) {
  return kind == MapKind::kNormalized && params.probability_map.superpixel_shares;
}

Result<cv::Mat1f> ObstacleComponentsMap(const MapAccumulation& accumulated, cv::Size image_size,
                                        const PipelineParams& params, MapKind kind,
                                        const cv::Mat1f& served) {
  if (!ObstaclesFromWholeBoxMap(params, kind)) return served;
  return PaintProbabilityMap(accumulated, image_size, /*superpixel_shares=*/false);
}

namespace {

// The map a detection serves and, when the obstacles come from a map of their own
// (ObstaclesFromWholeBoxMap), that map (else `components` stays empty). The two are painted from
// the same boxes and read nothing of each other: side by side when the request has two threads.
struct FrameMaps {
  cv::Mat1f served;
  cv::Mat1f components;
};
Result<FrameMaps> PaintFrameMaps(const std::vector<ScoredBox>& fused_boxes,
                                 const MapAccumulation& accumulated, cv::Size image_size,
                                 const OcclusionEdges& oaocc, const PipelineParams& params,
                                 MapKind kind, int threads) {
  Result<cv::Mat1f> served = Status::Internal("map not painted");
  Result<cv::Mat1f> whole_boxes = Status::Internal("map not painted");
  const bool separate = ObstaclesFromWholeBoxMap(params, kind);
  const auto paint = [&](int which) {
    if (which == 0)
      served = ServedProbabilityMap(fused_boxes, accumulated, image_size, oaocc, params, kind);
    else
      whole_boxes = PaintProbabilityMap(accumulated, image_size, /*superpixel_shares=*/false);
    return Status::Ok();
  };
  for (const Status& s : ParallelFor(separate ? 2 : 1, threads, paint))
    if (!s.ok()) return s;
  if (!served.ok()) return served.status();
  if (separate && !whole_boxes.ok()) return whole_boxes.status();
  return FrameMaps{std::move(*served), separate ? std::move(*whole_boxes) : cv::Mat1f()};
}

// The manifest's training data: one root, or several joined by " + ".
std::string TrainedOn(const nlohmann::json& training) {
  if (!training.is_object() || !training.contains("data")) return {};
  const nlohmann::json& data = training["data"];
  if (data.is_string()) return data.get<std::string>();
  std::string joined;
  if (data.is_array())
    for (const auto& root : data)
      if (root.is_string()) joined += (joined.empty() ? "" : " + ") + root.get<std::string>();
  return joined;
}

}  // namespace

ObstacleDetector::ObstacleDetector(ModelBundle bundle, std::string name)
    : bundle_(std::move(bundle)) {
  info_.name = std::move(name);
  info_.version = bundle_.version;
  info_.format_version = kBundleFormatVersion;
  info_.created = bundle_.created;
  info_.trained_on = TrainedOn(bundle_.training);
  info_.edge_source = EnumString(bundle_.edge_kind);
  info_.manifest = {{"version", bundle_.version},
                    {"created", bundle_.created},
                    {"edge_source", EnumString(bundle_.edge_kind)},
                    {"params", ToJson(bundle_.params)},
                    {"regions", bundle_.regions.ToJson()},
                    {"size_filter", bundle_.size_filter.ToJson()},
                    {"training", bundle_.training},
                    {"eval", bundle_.eval}};
}

namespace {

// A frame and options the detector can serve, checked before any stage runs: a map the bundle
// cannot make is refused now, not after the whole frame.
Status CheckRequest(const cv::Mat3b& bgr, const DetectOptions& options,
                    const PipelineParams& params) {
  if (bgr.empty()) return Status::InvalidArgument("empty image");
  if (bgr.cols < 16 || bgr.rows < 16)
    return Status::InvalidArgument("image too small: " + std::to_string(bgr.cols) + "x" +
                                   std::to_string(bgr.rows) + " (at least 16x16)");
  if (options.map_kind == MapKind::kCalibrated)
    return CalibratedMapAvailable(params.obstacle_calibration);
  return Status::Ok();
}

// The `max_proposals` best proposals by fused score (ties: by ORDR, then list order).
std::vector<Proposal> BestProposals(const RegressedProposals& regressed,
                                    const std::vector<ScoredBox>& fused, int max_proposals) {
  std::vector<std::size_t> order(fused.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (fused[a].score != fused[b].score) return fused[a].score > fused[b].score;
    return regressed.ordr[a] > regressed.ordr[b];
  });
  const std::size_t n = std::min<std::size_t>(order.size(), std::max(0, max_proposals));
  std::vector<Proposal> best;
  best.reserve(n);
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = order[r];
    best.push_back({fused[i].box, fused[i].score, regressed.ordr[i], regressed.obdr[i]});
  }
  return best;
}

}  // namespace

Result<Detection> ObstacleDetector::Detect(const cv::Mat3b& bgr,
                                           const DetectOptions& options) const {
  return Detect(bgr, options, nullptr);
}

Result<Detection> ObstacleDetector::Detect(const cv::Mat3b& bgr, const DetectOptions& options,
                                           FrameTrace* trace) const {
  FrameTrace local;  // the stages' results; handed to the caller when it asks for them
  FrameTrace& frame = trace != nullptr ? *trace : local;
  frame = FrameTrace{};
  if (Status st = CheckRequest(bgr, options, bundle_.params); !st.ok()) return st;
  StageTimer timer(options.cancelled);  // asks options.cancelled at every stage boundary
  const FrameBudget budget(std::chrono::steady_clock::now(), options.budget_ms);
  const int threads = std::max(1, options.threads);
  frame.geometry = CalibratedGeometryForFrame(
      bundle_, bgr, {.calibrate = options.calibrate, .camera = options.camera.get()});
  timer.Mark("calibration");
  const MultilayerRegions& regions = frame.geometry.regions;
  Result<OcclusionEdges> computed =
      ComputeOcclusionEdges(bgr, regions, *bundle_.edges, &bundle_.occlusion, bundle_.params,
                            /*enhance=*/true, &timer, &budget);
  if (!computed.ok()) return computed.status();
  if (!timer.stopped().ok()) return timer.stopped();
  frame.oaocc = std::move(computed).value();
  const OcclusionEdges& oaocc = frame.oaocc;
  // E and Ê are not read after this point, but they stay until the frame ends: released here
  // they left a hole the proposal stage's larger tables could not use, and the process's peak
  // RSS over 20 real frames rose 190 -> 199 MB although the live heap's peak fell.
  ProposalOptions proposal_options = DetectorProposalOptions(bundle_.params, regions.num_layers());
  proposal_options.deadline = budget.ProposalsDeadline();
  proposal_options.threads = threads;
  frame.regions = ProposeRegions(oaocc, regions, bundle_.params.boxes, proposal_options,
                                 frame.geometry.size_filter);
  // The regions' merge is one thread's work (a greedy NMS over some 30 000 boxes). R1's colour
  // tables for the features read the image alone, so a second thread builds them meanwhile; one
  // thread builds them at the features stage. Either way the same tables. (Started with the
  // frame or after the edges, the tables slowed the stages they ran beside, whose stripes and
  // chained sweeps wait for their slowest thread; docs/findings.md.)
  ProposalSet proposals;
  FrameColourTables colour_tables;
  const auto merge_or_tables = [&](int task) {
    if (task == 0) {
      proposals = MergeFrameRegions(frame.regions, proposal_options.merge_iou);
      // The regions' own boxes are freed with the merge unless the caller keeps them.
      if (trace == nullptr) frame.regions = {};
    } else {
      colour_tables = BuildFrameColourTables(
          bgr, oaocc.r1,
          FeatureOptionsForFrame(bundle_, bgr.cols, bgr.rows, frame.geometry.horizon.shift));
    }
    return Status::Ok();
  };
  for (const Status& s : ParallelFor(threads > 1 ? 2 : 1, 2, merge_or_tables))
    if (!s.ok()) return s;
  timer.Mark("proposals");
  if (!timer.stopped().ok()) return timer.stopped();
  Detection out;
  out.horizon = frame.geometry.horizon;
  if (regions.num_layers() > 0) out.road_region = regions.layers.front();
  if (oaocc.occlusion_cut_short) out.degraded_stages.push_back("occlusion");
  if (!proposals.truncated_regions.empty()) out.degraded_stages.push_back("proposals");
  frame.regressed = RegressProposals(bundle_, bgr, oaocc, regions, std::move(proposals), &timer,
                                     {.deadline = budget.RegressionDeadline(),
                                      .threads = threads,
                                      .horizon_shift = frame.geometry.horizon.shift},
                                     std::move(colour_tables));
  if (!timer.stopped().ok()) return timer.stopped();
  if (frame.regressed.truncated) out.degraded_stages.push_back("regression");
  if (Status st = PaintMaps(bgr.size(), options, threads, frame); !st.ok()) return st;
  out.map_kind = options.map_kind;
  out.width = bgr.cols;
  out.height = bgr.rows;
  out.obstacles =
      ScoreObstacles(frame.components, frame.accumulated.boxes, bundle_.params, options);
  timer.Mark("probability_map");

  out.proposals = BestProposals(frame.regressed, frame.fused, options.max_proposals);
  if (options.want_probability_map) out.probability = frame.served;
  out.timings = timer.times();
  return out;
}

Status ObstacleDetector::PaintMaps(cv::Size image_size, const DetectOptions& options, int threads,
                                   FrameTrace& frame) const {
  const RegressedProposals& regressed = frame.regressed;
  const std::vector<float> fused =
      FuseScores(regressed.ordr, regressed.obdr, bundle_.params.fusion);
  frame.fused.resize(fused.size());
  for (std::size_t i = 0; i < fused.size(); ++i)
    frame.fused[i] = {regressed.proposals.boxes[i].box, fused[i]};
  frame.accumulated = AccumulatedBoxes(frame.fused, bundle_.params.probability_map);
  Result<FrameMaps> maps = PaintFrameMaps(frame.fused, frame.accumulated, image_size, frame.oaocc,
                                          bundle_.params, options.map_kind, threads);
  if (!maps.ok()) return maps.status();
  frame.served = std::move(maps->served);
  frame.components = maps->components.empty() ? frame.served : std::move(maps->components);
  return Status::Ok();
}

Result<std::shared_ptr<const Detector>> Detector::Load(const std::string& model_dir) {
  auto bundle = LoadModelBundle(model_dir);
  if (!bundle.ok()) return bundle.status();
  std::filesystem::path path = std::filesystem::path(model_dir).lexically_normal();
  if (!path.has_filename()) path = path.parent_path();  // "models/default/"
  const std::string name = path.filename().string();
  return std::shared_ptr<const Detector>(
      std::make_shared<ObstacleDetector>(std::move(*bundle), name.empty() ? "model" : name));
}

}  // namespace tod
