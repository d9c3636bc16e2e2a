#include "core/pipeline/evaluator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <opencv2/ximgproc/edgeboxes.hpp>
#include <sstream>

#include "core/metrics/instance_recall.h"
#include "core/pipeline/dataset_factory.h"
#include "core/pipeline/edge_boxes_baseline.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/parallel.h"

namespace tod {
namespace {

constexpr int kMaxProposals = 1000;
const std::vector<int> kTableN = {200, 400, 600, 800, 1000};

std::vector<Box> BoxesOf(const std::vector<ScoredBox>& boxes) {
  std::vector<Box> out;
  out.reserve(boxes.size());
  for (const auto& b : boxes) out.push_back(b.box);
  return out;
}

VariantCurves Curves(const RecallAccumulator& acc) {
  VariantCurves c;
  for (int n = 0; n <= kMaxProposals; n += 5) {
    c.n_grid.push_back(n);
    c.recall_at_07.push_back(acc.Recall(n, 0.7));
    c.average_recall.push_back(acc.AverageRecall(n));
  }
  for (double tau : RecallIouThresholds()) {
    c.iou_grid.push_back(tau);
    c.recall_at_1000.push_back(acc.Recall(kMaxProposals, tau));
  }
  for (int n : kTableN) c.ar_table[n] = acc.AverageRecall(n);
  return c;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

std::string Fixed(double v, int digits = 3) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// An undefined metric (NaN) is null in the JSON rather than a number a reader might average.
nlohmann::json NumberOrNull(double v) {
  if (std::isnan(v)) return nullptr;
  return v;
}

}  // namespace

Result<EvalReport> EvaluateModel(const ModelBundle& bundle, const EvalOptions& options) {
  auto selection = SelectFrames(
      {options.data_root, options.split, options.format, options.split_file, options.max_frames});
  if (!selection.ok()) return selection.status();
  const Dataset& dataset = *selection->dataset;
  const int n = static_cast<int>(selection->frames.size());

  std::map<std::string, RecallAccumulator> recall;
  for (const auto& v : ProposalVariants()) recall.emplace(v, RecallAccumulator(kMaxProposals));
  for (const auto& v : RegressionVariants()) recall.emplace(v, RecallAccumulator(kMaxProposals));
  const bool calibrated_map = bundle.params.obstacle_calibration.fitted;
  std::vector<std::string> map_variants = RegressionVariants();
  if (calibrated_map) map_variants.push_back(kCalibratedMapVariant);
  std::map<std::string, PixelRocAccumulator> roc;
  std::map<std::string, PixelHistogramAccumulator> served_map_histograms;  // AP, FPR95
  for (const auto& v : map_variants) {
    roc.emplace(v, PixelRocAccumulator());
    served_map_histograms.emplace(v, PixelHistogramAccumulator());
  }
  std::map<std::string, std::vector<double>> stage_ms;
  ReportedObstacleCounts alarms;
  bool road_labelled = false, not_obstacle = false;
  std::vector<std::string> stage_order;
  std::mutex mutex;
  int done = 0;

  const std::vector<Status> per_frame = ParallelFor(n, options.threads, [&](int i) -> Status {
    auto loaded = dataset.Load(selection->frames[i]);
    if (!loaded.ok()) return loaded.status();
    const Sample& s = *loaded;
    const FrameGeometry geo = GeometryForFrame(bundle, s.image.cols, s.image.rows);
    const int layers = geo.regions.num_layers();

    // Proposal-only baselines on plain (not obstacle-aware) edges. OLP@1 must not run the
    // occlusion classifier, which learned its features on enhanced edges Ê: it scores each
    // superpixel boundary by its mean plain E instead (the untrained boundary strength of §3.4),
    // so OLP@1 -> OAOCC+OLP@1 measures enhancement plus the trained obstacle-aware classifier.
    const OcclusionClassifier untrained_boundaries;
    PipelineParams plain_params = bundle.params;
    plain_params.prior_correction.occlusion_odds = 1.0;  // mean E is no classifier probability
    const Result<OcclusionEdges> plain_computed =
        ComputeOcclusionEdges(s.image, geo.regions, *bundle.edges, &untrained_boundaries,
                              OcclusionFeatureOptions{}, plain_params, /*enhance=*/false);
    if (!plain_computed.ok()) return plain_computed.status();
    const OcclusionEdges& plain = *plain_computed;
    const std::vector<Box> eb = EdgeBoxesBaseline(plain.base_edge, plain.r1, kMaxProposals);
    const ProposalSet olp1 = ProposeBoxes(
        plain, geo.regions, bundle.params.boxes,
        {1, false, bundle.params.size_filter, bundle.params.region_merge_iou}, geo.size_filter);

    // The detector's own path (timed): enhanced edges, BP = OAOCC+OLP@4+MS, regression, map.
    StageTimer timer;
    const Result<OcclusionEdges> computed =
        ComputeOcclusionEdges(s.image, geo.regions, *bundle.edges, &bundle.occlusion,
                              OcclusionFeatureOptionsForFrame(bundle, s.image.cols, s.image.rows),
                              bundle.params, /*enhance=*/true, &timer);
    if (!computed.ok()) return computed.status();
    const OcclusionEdges& oaocc = *computed;
    const SizeFilter* filter = bundle.params.size_filter ? &geo.size_filter : nullptr;
    std::vector<RegionProposals> ms_regions;
    for (int k = 0; k < layers; ++k)
      ms_regions.push_back(
          ProposeRegionBoxes(oaocc, geo.regions, bundle.params.boxes, k, true, filter));
    ProposalSet bp = MergeRegionBoxes(ms_regions, bundle.params.region_merge_iou);
    timer.Mark("proposals");
    // R1's stride factor is 1 with and without MS, so its boxes serve OAOCC+OLP@1 and OP too;
    // only R2..RK are scored again without MS.
    const std::vector<Box> oaocc1 = BoxesOf(ms_regions.front().boxes);
    std::vector<RegionProposals> plain_regions = {ms_regions.front()};
    for (int k = 1; k < layers; ++k)
      plain_regions.push_back(
          ProposeRegionBoxes(oaocc, geo.regions, bundle.params.boxes, k, false, filter));
    const std::vector<Box> bp_boxes = RankedOnCommonScale(bp);
    const RegressedProposals bp_reg =
        RegressProposals(bundle, s.image, oaocc, geo.regions, std::move(bp), &timer);
    const std::vector<float> fused = FuseScores(bp_reg.ordr, bp_reg.obdr, bundle.params.fusion);
    std::vector<ScoredBox> bp_fusion(fused.size()), bp_ordr(fused.size());
    for (std::size_t j = 0; j < fused.size(); ++j) {
      bp_fusion[j] = {bp_reg.proposals.boxes[j].box, fused[j]};
      bp_ordr[j] = {bp_reg.proposals.boxes[j].box, bp_reg.ordr[j]};
    }
    const MapSuperpixels superpixels{oaocc.superpixels, oaocc.r1};
    const MapAccumulation fusion_boxes = AccumulatedBoxes(bp_fusion, bundle.params.probability_map);
    Result<cv::Mat1f> fusion_made =
        PaintProbabilityMap(fusion_boxes, s.image.size(),
                            bundle.params.probability_map.superpixel_shares, &superpixels);
    if (!fusion_made.ok()) return fusion_made.status();
    const cv::Mat1f map_fusion = std::move(fusion_made).value();
    timer.Mark("probability_map");

    ProposalSet op = MergeRegionBoxes(plain_regions, bundle.params.region_merge_iou);
    const std::vector<Box> op_boxes = RankedOnCommonScale(op);
    const RegressedProposals op_reg =
        RegressProposals(bundle, s.image, oaocc, geo.regions, std::move(op));
    std::vector<ScoredBox> op_ordr(op_reg.ordr.size());
    for (std::size_t j = 0; j < op_ordr.size(); ++j)
      op_ordr[j] = {op_reg.proposals.boxes[j].box, op_reg.ordr[j]};
    Result<cv::Mat1f> bp_ordr_made = AccumulateProbabilityMap(
        bp_ordr, s.image.size(), bundle.params.probability_map, &superpixels);
    Result<cv::Mat1f> op_ordr_made = AccumulateProbabilityMap(
        op_ordr, s.image.size(), bundle.params.probability_map, &superpixels);
    if (!bp_ordr_made.ok()) return bp_ordr_made.status();
    if (!op_ordr_made.ok()) return op_ordr_made.status();
    const cv::Mat1f map_bp_ordr = std::move(bp_ordr_made).value();
    const cv::Mat1f map_op_ordr = std::move(op_ordr_made).value();
    const float min_score = bundle.params.probability_map.min_score;
    cv::Mat1f map_calibrated;
    if (calibrated_map) {
      Result<cv::Mat1f> made = ServedProbabilityMap(bp_fusion, fusion_boxes, s.image.size(), oaocc,
                                                    bundle.params, MapKind::kCalibrated);
      if (!made.ok()) return made.status();
      map_calibrated = std::move(*made);
    }

    // Reported obstacles at the detector's defaults (calibrated score >= 0.5), from the map the
    // detector takes them from.
    Result<cv::Mat1f> obstacle_made = ObstacleComponentsMap(
        fusion_boxes, s.image.size(), bundle.params, MapKind::kNormalized, map_fusion);
    if (!obstacle_made.ok()) return obstacle_made.status();
    const cv::Mat1f obstacle_map = std::move(obstacle_made).value();
    const std::vector<DetectedObstacle> reported =
        ScoreObstacles(obstacle_map, fusion_boxes.boxes, bundle.params, DetectOptions{});
    int false_alarms = 0;
    for (const DetectedObstacle& o : reported)
      false_alarms += cv::countNonZero(s.obstacle(o.box.rect())) == 0;
    int found = 0;
    for (const ObstacleInstance& inst : s.instances)
      for (const DetectedObstacle& o : reported)
        if (!Intersect(o.box, inst.box).empty()) {
          ++found;
          break;
        }

    std::vector<Box> gt;
    for (const auto& inst : s.instances) gt.push_back(inst.box);
    std::lock_guard lock(mutex);
    // A map that does not match its frame's masks is this frame's error, not a silent gap in
    // the pooled pixel counts. First, so that a failing frame is counted nowhere (every map has
    // the frame's size, so the first variant decides).
    const auto add_pixels = [&](const std::string& variant, const cv::Mat1f& map) {
      if (Status st = roc.at(variant).Add(map, s.obstacle, s.road); !st.ok()) return st;
      return served_map_histograms.at(variant).Add(map, s.obstacle, s.road);
    };
    for (const auto& [variant, map] :
         {std::pair{"OP+ORDR@4", &map_op_ordr}, std::pair{"BP+ORDR@4", &map_bp_ordr},
          std::pair{"BP+Fusion@4", &map_fusion}}) {
      if (Status st = add_pixels(variant, *map); !st.ok()) return st.WithContext(variant);
    }
    if (calibrated_map) {
      if (Status st = add_pixels(kCalibratedMapVariant, map_calibrated); !st.ok())
        return st.WithContext(kCalibratedMapVariant);
    }
    alarms.false_alarms += false_alarms;
    (s.free_space == FreeSpace::kRoadLabel ? road_labelled : not_obstacle) = true;
    alarms.instances_found += found;
    if (s.instances.empty()) {
      ++alarms.obstacle_free_frames;
      alarms.false_alarms_on_obstacle_free += false_alarms;
    }
    recall.at("EB").Add(eb, gt);
    recall.at("OLP@1").Add(BoxesOf(olp1.boxes), gt);
    recall.at("OAOCC+OLP@1").Add(oaocc1, gt);
    recall.at("OAOCC+OLP@4").Add(op_boxes, gt);
    recall.at("OAOCC+OLP@4+MS").Add(bp_boxes, gt);
    recall.at("OP+ORDR@4").Add(BoxesOf(RankedAboveThreshold(op_ordr, min_score)), gt);
    recall.at("BP+ORDR@4").Add(BoxesOf(RankedAboveThreshold(bp_ordr, min_score)), gt);
    recall.at("BP+Fusion@4").Add(BoxesOf(RankedAboveThreshold(bp_fusion, min_score)), gt);
    for (const auto& [stage, ms] : timer.times()) {
      if (!stage_ms.count(stage)) stage_order.push_back(stage);
      stage_ms[stage].push_back(ms);
    }
    stage_ms["total"].push_back(timer.total_ms());
    ++done;
    if (options.progress && (done % 10 == 0 || done == n))
      options.progress("evaluated " + std::to_string(done) + "/" + std::to_string(n) + " frames");
    return Status::Ok();
  });
  EvalReport report;
  const Status bad = ApplyBadFramePolicy(
      per_frame, [&](int i) { return dataset.name(selection->frames[i]); }, options.on_bad_frame,
      &report.skipped);
  if (!bad.ok()) return bad;
  report.frames = n - static_cast<int>(report.skipped.size());
  report.instances = recall.at("EB").instances();
  report.reported = alarms;
  report.map_isolation_exponent = bundle.params.probability_map.isolation.exponent;
  report.map_superpixel_shares = bundle.params.probability_map.superpixel_shares;
  report.proposal_features = bundle.ordr.num_features();
  report.proposal_feature_set = ProposalFeatureSet(bundle.params);
  report.free_space = road_labelled && not_obstacle
                          ? "mixed: the road label where the frame has one, else every non-void "
                            "non-obstacle pixel"
                      : not_obstacle
                          ? "every non-void pixel that is not an obstacle (no road label)"
                          : "the road label (free space)";
  for (const auto& v : ProposalVariants()) report.proposals[v] = Curves(recall.at(v));
  for (const auto& v : RegressionVariants()) report.regression[v] = Curves(recall.at(v));
  for (const auto& v : map_variants) {
    report.roc[v] = roc.at(v).Curve();
    for (double fpr : TableFprs()) report.tpr_at_fpr[v][fpr] = TprAtFpr(report.roc[v], fpr);
    const PixelHistogramAccumulator& histograms = served_map_histograms.at(v);
    report.average_precision[v] = histograms.Ap();
    report.fpr_at_tpr95[v] = histograms.FprAtTpr(0.95);
    report.precision_recall[v] = histograms.PrCurve();
  }
  stage_order.push_back("total");
  for (const auto& stage : stage_order)
    report.stage_median_ms.emplace_back(stage, Median(stage_ms[stage]));
  return report;
}

std::vector<std::string> PixelMapVariants(const EvalReport& report) {
  std::vector<std::string> variants = RegressionVariants();
  if (report.roc.count(kCalibratedMapVariant)) variants.push_back(kCalibratedMapVariant);
  return variants;
}

nlohmann::json EvalReportToJson(const EvalReport& r) {
  nlohmann::json j;
  j["frames"] = r.frames;
  j["instances"] = r.instances;
  j["skipped_frames"] = SkippedFramesToJson(r.skipped);
  const ReportedObstacleCounts& a = r.reported;
  const auto per = [](int count, int frames) -> nlohmann::json {
    return frames > 0 ? nlohmann::json(static_cast<double>(count) / frames) : nlohmann::json();
  };
  j["obstacles"] = {{"min_obstacle_score", DetectOptions{}.min_obstacle_score},
                    {"false_alarms_per_frame", per(a.false_alarms, r.frames)},
                    {"obstacle_free_frames", a.obstacle_free_frames},
                    {"false_alarms_per_obstacle_free_frame",
                     per(a.false_alarms_on_obstacle_free, a.obstacle_free_frames)},
                    {"instances_found", per(a.instances_found, r.instances)}};
  j["free_space"] = r.free_space;
  j["map_isolation_exponent"] = r.map_isolation_exponent;
  j["map_superpixel_shares"] = r.map_superpixel_shares;
  j["proposal_features"] = r.proposal_features;
  auto ar = [](const VariantCurves& c) {
    nlohmann::json a = nlohmann::json::object();
    for (const auto& [n, v] : c.ar_table) a[std::to_string(n)] = v;
    return a;
  };
  j["proposals"] = nlohmann::json::object();
  for (const auto& v : ProposalVariants()) j["proposals"][v] = {{"ar", ar(r.proposals.at(v))}};
  j["regression"] = nlohmann::json::object();
  for (const auto& v : RegressionVariants()) {
    nlohmann::json tpr = nlohmann::json::object();
    for (const auto& [fpr, t] : r.tpr_at_fpr.at(v)) tpr[Fixed(fpr)] = t;
    j["regression"][v] = {{"tpr_at_fpr", tpr},
                          {"ar", ar(r.regression.at(v))},
                          {"ap", NumberOrNull(r.average_precision.at(v))},
                          {"fpr_at_tpr95", NumberOrNull(r.fpr_at_tpr95.at(v))}};
  }
  j["calibrated_map"] = nullptr;
  if (r.roc.count(kCalibratedMapVariant)) {
    nlohmann::json tpr = nlohmann::json::object();
    for (const auto& [fpr, t] : r.tpr_at_fpr.at(kCalibratedMapVariant)) tpr[Fixed(fpr)] = t;
    j["calibrated_map"] = {
        {"boxes", "BP+Fusion@4"},
        {"tpr_at_fpr", tpr},
        {"ap", NumberOrNull(r.average_precision.at(kCalibratedMapVariant))},
        {"fpr_at_tpr95", NumberOrNull(r.fpr_at_tpr95.at(kCalibratedMapVariant))}};
  }
  j["timing_ms"] = nlohmann::json::object();
  for (const auto& [stage, ms] : r.stage_median_ms) j["timing_ms"][stage] = ms;
  return j;
}

std::string FormatEvalTables(const EvalReport& r) {
  std::ostringstream o;
  o << "frames " << r.frames << ", obstacle instances " << r.instances << "\n";
  o << "free space (FPR, AP negatives): " << r.free_space << "\n";
  o << "paper's map: "
    << (r.map_isolation_exponent > 0.f
            ? "each box weighted by its isolation^" + Fixed(r.map_isolation_exponent, 1)
            : std::string("no isolation weight"))
    << (r.map_superpixel_shares ? ", each pixel by its superpixel's share of the box"
                                : ", whole boxes")
    << "\n";
  o << "regressors: " << r.proposal_features << " proposal features (" << r.proposal_feature_set
    << ")\n";
  {
    const ReportedObstacleCounts& a = r.reported;
    char text[256];
    std::snprintf(text, sizeof text,
                  "reported obstacles (score >= %.2f): %.2f false alarms per frame, %.2f per "
                  "obstacle-free frame (%d such frames), %.2f of instances found\n",
                  DetectOptions{}.min_obstacle_score,
                  r.frames ? static_cast<double>(a.false_alarms) / r.frames : 0.0,
                  a.obstacle_free_frames ? static_cast<double>(a.false_alarms_on_obstacle_free) /
                                               a.obstacle_free_frames
                                         : 0.0,
                  a.obstacle_free_frames,
                  r.instances ? static_cast<double>(a.instances_found) / r.instances : 0.0);
    o << text;
  }
  for (const SkippedFrame& f : r.skipped)
    o << "skipped frame " << f.frame << ": " << f.reason << "\n";
  o << "\n";
  o << "Average recall (proposals)\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-16s %7s %7s %7s %7s %7s\n", "variant", "200", "400", "600",
                "800", "1000");
  o << line;
  auto ar_row = [&](const std::string& name, const VariantCurves& c) {
    std::snprintf(line, sizeof line, "%-16s", name.c_str());
    o << line;
    for (int n : kTableN)
      o << " " << std::string(7 - Fixed(c.ar_table.at(n)).size(), ' ') << Fixed(c.ar_table.at(n));
    o << "\n";
  };
  for (const auto& v : ProposalVariants()) ar_row(v, r.proposals.at(v));
  o << "\nPixel ROC: TPR at FPR (regression)\n";
  std::snprintf(line, sizeof line, "%-16s", "variant");
  o << line;
  for (double f : TableFprs()) o << "   " << Fixed(f);
  o << "\n";
  for (const auto& v : PixelMapVariants(r)) {
    std::snprintf(line, sizeof line, "%-16s", v.c_str());
    o << line;
    for (double f : TableFprs()) o << "   " << Fixed(r.tpr_at_fpr.at(v).at(f));
    o << "\n";
  }
  o << "\nPixel AP and FPR at 95 % TPR (8-bit map, regression)\n";
  std::snprintf(line, sizeof line, "%-16s %7s %7s\n", "variant", "AP", "FPR95");
  o << line;
  const auto defined = [](double v) { return std::isnan(v) ? std::string("n/a") : Fixed(v); };
  for (const auto& v : PixelMapVariants(r)) {
    std::snprintf(line, sizeof line, "%-16s %7s %7s\n", v.c_str(),
                  defined(r.average_precision.at(v)).c_str(),
                  defined(r.fpr_at_tpr95.at(v)).c_str());
    o << line;
  }
  if (r.roc.count(kCalibratedMapVariant))
    o << "(" << kCalibratedMapVariant
      << ": the calibrated map of BP+Fusion@4's boxes, not divided by the frame's maximum)\n";
  o << "\nAverage recall (regressed, score > 0.25)\n";
  for (const auto& v : RegressionVariants()) ar_row(v, r.regression.at(v));
  o << "\nMedian time per frame (ms)\n";
  for (const auto& [stage, ms] : r.stage_median_ms) {
    std::snprintf(line, sizeof line, "%-16s %9.1f\n", stage.c_str(), ms);
    o << line;
  }
  return o.str();
}

}  // namespace tod
