#include "core/evaluation/evaluator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

#include "core/calibration/camera_horizon.h"
#include "core/calibration/camera_registry.h"
#include "core/calibration/horizon_estimator.h"
#include "core/datasets/dataset_factory.h"
#include "core/evaluation/component_evaluation.h"
#include "core/evaluation/frame_evaluation.h"
#include "core/metrics/instance_recall.h"
#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/parallel.h"

namespace tod {
namespace {

const std::vector<int> kTableN = {200, 400, 600, 800, 1000};
// The map `tod detect` serves at its defaults (MapKind::kNormalized).
constexpr const char* kServedMapVariant = "BP+Fusion@4";

VariantCurves Curves(const RecallAccumulator& acc) {
  VariantCurves c;
  for (int n = 0; n <= kEvalMaxProposals; n += 5) {
    c.n_grid.push_back(n);
    c.recall_at_07.push_back(acc.Recall(n, 0.7));
    c.average_recall.push_back(acc.AverageRecall(n));
  }
  for (double tau : RecallIouThresholds()) {
    c.iou_grid.push_back(tau);
    c.recall_at_1000.push_back(acc.Recall(kEvalMaxProposals, tau));
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

const char* EvalGeometryName(EvalGeometry geometry) {
  switch (geometry) {
    case EvalGeometry::kCamera:
      return "camera";
    case EvalGeometry::kBundle:
      return "bundle";
    case EvalGeometry::kFrame:
      break;
  }
  return "frame";
}

std::optional<EvalGeometry> ParseEvalGeometry(const std::string& name) {
  for (const EvalGeometry g : {EvalGeometry::kFrame, EvalGeometry::kCamera, EvalGeometry::kBundle})
    if (name == EvalGeometryName(g)) return g;
  return std::nullopt;
}

namespace {

// The split's running totals: recall per variant, pixel counts per map variant, the reported
// obstacles and the stage times. The caller serialises Add() and calls it in frame order.
class EvalTotals {
 public:
  explicit EvalTotals(bool calibrated_map) : map_variants_(RegressionVariants()) {
    for (const auto& v : ProposalVariants())
      recall_.emplace(v, RecallAccumulator(kEvalMaxProposals));
    for (const auto& v : RegressionVariants())
      recall_.emplace(v, RecallAccumulator(kEvalMaxProposals));
    if (calibrated_map) map_variants_.push_back(kCalibratedMapVariant);
    for (const auto& v : map_variants_) {
      roc_.emplace(v, PixelRocAccumulator());
      histograms_.emplace(v, PixelHistogramAccumulator());
    }
    component_maps_.emplace(kServedMapVariant, ComponentMapStore());
    if (calibrated_map) component_maps_.emplace(kCalibratedMapVariant, ComponentMapStore());
  }

  Status Add(const FrameEvaluation& frame, const Sample& s) {
    // A map that does not match its frame's masks is this frame's error, not a silent gap in
    // the pooled pixel counts. First, so that a failing frame is counted nowhere (every map has
    // the frame's size, so the first variant decides).
    for (const auto& [variant, map] : frame.maps) {
      Status st = roc_.at(variant).Add(map, s.obstacle, s.road);
      if (st.ok()) st = histograms_.at(variant).Add(map, s.obstacle, s.road);
      if (!st.ok()) return st.WithContext(variant);
      const auto kept = component_maps_.find(variant);
      if (kept == component_maps_.end()) continue;
      if (Status st = kept->second.Add(map, s); !st.ok()) return st.WithContext(variant);
    }
    reported_.false_alarms += frame.reported.false_alarms;
    reported_.instances_found += frame.reported.instances_found;
    reported_.found_iou25 += frame.reported.found_iou25;
    reported_.found_iou50 += frame.reported.found_iou50;
    reported_components_.Add(frame.reported_components);
    if (s.instances.empty()) {
      ++reported_.obstacle_free_frames;
      reported_.false_alarms_on_obstacle_free += frame.reported.false_alarms;
    }
    for (const auto& [rule, counts] : frame.list_sweep) list_sweep_[rule] += counts;
    (s.free_space == FreeSpace::kRoadLabel ? road_labelled_ : not_obstacle_) = true;
    std::vector<Box> gt;
    for (const auto& inst : s.instances) gt.push_back(inst.box);
    for (const auto& [variant, boxes] : frame.ranked) recall_.at(variant).Add(boxes, gt);
    for (const auto& [stage, ms] : frame.stage_times) {
      if (!stage_ms_.count(stage)) stage_order_.push_back(stage);
      stage_ms_[stage].push_back(ms);
    }
    stage_ms_["total"].push_back(frame.total_ms);
    ++geometry_sources_[HorizonSourceName(frame.horizon.source)];
    abs_shifts_.push_back(std::abs(frame.horizon.shift));
    return Status::Ok();
  }

  // Everything pooled, then the component metrics of each kept map at its best-F1 threshold.
  Status Fill(EvalReport& report, int threads) const {
    report.instances = recall_.at("EB").instances();
    report.reported = reported_;
    report.reported.components = reported_components_.Summary();
    report.list_sweep = list_sweep_;
    report.geometry_sources = geometry_sources_;
    report.median_abs_shift_rows = Median(abs_shifts_);
    for (const auto& [variant, store] : component_maps_) {
      MapComponents& c = report.components[variant];
      c.level = histograms_.at(variant).BestF1Level();
      if (c.level < 0) continue;  // no obstacle pixel: no threshold of best F1
      Result<ComponentSummary> measured = store.Measure(c.level, threads);
      if (!measured.ok()) return measured.status().WithContext(variant);
      c.summary = std::move(measured).value();
    }
    report.free_space = road_labelled_ && not_obstacle_
                            ? "mixed: the road label where the frame has one, else every non-void "
                              "non-obstacle pixel"
                        : not_obstacle_
                            ? "every non-void pixel that is not an obstacle (no road label)"
                            : "the road label (free space)";
    for (const auto& v : ProposalVariants()) report.proposals[v] = Curves(recall_.at(v));
    for (const auto& v : RegressionVariants()) report.regression[v] = Curves(recall_.at(v));
    for (const auto& v : map_variants_) {
      report.roc[v] = roc_.at(v).Curve();
      for (double fpr : TableFprs()) report.tpr_at_fpr[v][fpr] = TprAtFpr(report.roc[v], fpr);
      const PixelHistogramAccumulator& histograms = histograms_.at(v);
      report.average_precision[v] = histograms.Ap();
      report.fpr_at_tpr95[v] = histograms.FprAtTpr(0.95);
      report.precision_recall[v] = histograms.PrCurve();
    }
    std::vector<std::string> stages = stage_order_;
    stages.push_back("total");
    for (const auto& stage : stages) {
      const auto times = stage_ms_.find(stage);
      report.stage_median_ms.emplace_back(stage,
                                          times == stage_ms_.end() ? 0.0 : Median(times->second));
    }
    return Status::Ok();
  }

 private:
  std::vector<std::string> map_variants_;
  std::map<std::string, RecallAccumulator> recall_;
  std::map<std::string, PixelRocAccumulator> roc_;
  std::map<std::string, PixelHistogramAccumulator> histograms_;  // AP, FPR95
  std::map<std::string, ComponentMapStore> component_maps_;
  ReportedObstacleCounts reported_;
  ComponentAccumulator reported_components_;
  std::map<std::string, ObstacleListCounts> list_sweep_;
  bool road_labelled_ = false, not_obstacle_ = false;
  std::vector<std::string> stage_order_;
  std::map<std::string, std::vector<double>> stage_ms_;
  std::map<std::string, int> geometry_sources_;
  std::vector<double> abs_shifts_;
};

// EvalGeometry::kCamera: every frame's own horizon estimate, as the share of its height a
// CameraTrack keeps (none where the frame has none or the bundle no reference). Frames that do
// not load have none here; the evaluation reports their error.
std::vector<std::optional<double>> CameraFrameShares(const ModelBundle& bundle,
                                                     const Dataset& dataset,
                                                     const std::vector<int>& frames, int threads) {
  std::vector<std::optional<double>> shares(frames.size());
  ParallelFor(static_cast<int>(frames.size()), threads, [&](int i) -> Status {
    Result<Sample> loaded = dataset.Load(frames[i]);
    if (!loaded.ok() || !BundleHorizonRow(bundle, loaded->image.cols, loaded->image.rows))
      return Status::Ok();
    const HorizonEstimate estimate = EstimateHorizon(loaded->image);
    if (estimate.found) shares[i] = estimate.row / loaded->image.rows;
    return Status::Ok();
  });
  return shares;
}

// The detector's options for frame i: the defaults, calibrated as `geometry` says. A camera
// frame gets a track that has seen every other frame of the split, so that with its own estimate
// it stands on the camera's median over the whole split, whatever order the frames run in.
DetectOptions FrameDetectOptions(EvalGeometry geometry,
                                 const std::vector<std::optional<double>>& camera_shares, int i) {
  DetectOptions options;
  options.calibrate = geometry != EvalGeometry::kBundle;
  if (geometry != EvalGeometry::kCamera) return options;
  CameraHorizon seen;
  for (int j = 0; j < static_cast<int>(camera_shares.size()); ++j)
    if (j != i && camera_shares[j]) seen.Add(*camera_shares[j]);
  options.camera = std::make_shared<CameraTrack>(seen);
  return options;
}

// One frame's evaluation with the sample it was measured on, waiting for its turn in the totals.
struct EvaluatedFrame {
  FrameEvaluation evaluation;
  Sample sample;
};

}  // namespace

Result<EvalReport> EvaluateModel(const ModelBundle& bundle, const EvalOptions& options) {
  auto selection = SelectFrames(options.data.Spec());
  if (!selection.ok()) return selection.status();
  const Dataset& dataset = *selection->dataset;
  const int n = static_cast<int>(selection->frames.size());
  EvalTotals totals(bundle.params.obstacle_calibration.fitted);
  const ObstacleDetector detector(bundle, "eval");  // one copy of the bundle for the run
  const std::vector<std::optional<double>> camera_shares =
      options.geometry == EvalGeometry::kCamera
          ? CameraFrameShares(bundle, dataset, selection->frames, options.threads)
          : std::vector<std::optional<double>>();
  // Frames finish in any order, but the totals are added in frame order: pooled floating-point
  // means (sIoU, PPV) then do not depend on the thread count or on scheduling.
  std::mutex mutex;
  std::map<int, std::optional<EvaluatedFrame>> finished;  // nullopt: the frame failed
  std::vector<Status> added(n, Status::Ok());
  int next_to_add = 0;
  const auto finish = [&](int i, std::optional<EvaluatedFrame> frame) {
    std::lock_guard lock(mutex);
    finished.emplace(i, std::move(frame));
    for (auto it = finished.find(next_to_add); it != finished.end();
         it = finished.find(next_to_add)) {
      if (it->second) added[next_to_add] = totals.Add(it->second->evaluation, it->second->sample);
      finished.erase(it);
      ++next_to_add;
      if (options.progress && (next_to_add % 10 == 0 || next_to_add == n))
        options.progress("evaluated " + std::to_string(next_to_add) + "/" + std::to_string(n) +
                         " frames");
    }
  };
  std::vector<Status> per_frame = ParallelFor(n, options.threads, [&](int i) -> Status {
    Result<Sample> loaded = dataset.Load(selection->frames[i]);
    Result<FrameEvaluation> frame =
        loaded.ok() ? EvaluateFrame(detector, *loaded,
                                    FrameDetectOptions(options.geometry, camera_shares, i))
                    : Result<FrameEvaluation>(loaded.status());
    if (!frame.ok()) {
      finish(i, std::nullopt);
      return frame.status();
    }
    Sample sample = std::move(loaded).value();
    sample.image.release();  // the totals need the masks only
    finish(i, EvaluatedFrame{std::move(frame).value(), std::move(sample)});
    return Status::Ok();
  });
  for (int i = 0; i < n; ++i)
    if (per_frame[i].ok()) per_frame[i] = added[i];
  EvalReport report;
  const Status bad = ApplyBadFramePolicy(
      per_frame, [&](int i) { return dataset.name(selection->frames[i]); },
      options.data.on_bad_frame, &report.skipped);
  if (!bad.ok()) return bad;
  report.frames = n - static_cast<int>(report.skipped.size());
  report.geometry = options.geometry;
  report.map_isolation_exponent = bundle.params.probability_map.isolation.exponent;
  report.map_superpixel_shares = bundle.params.probability_map.superpixel_shares;
  report.calibration_flat = bundle.params.obstacle_calibration.flat;
  report.proposal_features = bundle.ordr.num_features();
  report.proposal_feature_set = ProposalFeatureSet(bundle.params);
  if (Status st = totals.Fill(report, options.threads); !st.ok()) return st;
  return report;
}

std::vector<std::string> PixelMapVariants(const EvalReport& report) {
  std::vector<std::string> variants = RegressionVariants();
  if (report.roc.count(kCalibratedMapVariant)) variants.push_back(kCalibratedMapVariant);
  return variants;
}

std::vector<std::string> ComponentMapVariants(const EvalReport& report) {
  std::vector<std::string> variants;
  for (const auto& [variant, c] : report.components) variants.push_back(variant);
  return variants;
}

namespace {

nlohmann::json ComponentsToJson(const ComponentSummary& c) {
  nlohmann::json f1 = nlohmann::json::object();
  for (std::size_t i = 0; i < c.f1.size(); ++i)
    f1[Fixed(ComponentF1Thresholds()[i], 2)] = NumberOrNull(c.f1[i]);
  return {{"truth_components", c.truth_components},
          {"predicted_components", c.predicted_components},
          {"mean_siou", NumberOrNull(c.mean_siou)},
          {"mean_ppv", NumberOrNull(c.mean_ppv)},
          {"mean_f1", NumberOrNull(c.mean_f1)},
          {"f1_at_050", NumberOrNull(c.f1_at_050)},
          {"f1", f1}};
}

nlohmann::json MapComponentsToJson(const MapComponents& c) {
  if (c.level < 0) return nullptr;
  nlohmann::json j = ComponentsToJson(c.summary);
  j["threshold"] = c.level / 255.0;
  j["threshold_8bit"] = c.level;
  return j;
}

}  // namespace

nlohmann::json EvalReportToJson(const EvalReport& r) {
  nlohmann::json j;
  j["frames"] = r.frames;
  j["instances"] = r.instances;
  j["skipped_frames"] = SkippedFramesToJson(r.skipped);
  j["geometry"] = {{"mode", EvalGeometryName(r.geometry)},
                   {"sources", r.geometry_sources},
                   {"median_abs_shift_rows", r.median_abs_shift_rows}};
  const ReportedObstacleCounts& a = r.reported;
  const auto per = [](int count, int frames) -> nlohmann::json {
    return frames > 0 ? nlohmann::json(static_cast<double>(count) / frames) : nlohmann::json();
  };
  j["obstacles"] = {{"min_obstacle_score", DetectOptions{}.min_obstacle_score},
                    {"false_alarms_per_frame", per(a.false_alarms, r.frames)},
                    {"obstacle_free_frames", a.obstacle_free_frames},
                    {"false_alarms_per_obstacle_free_frame",
                     per(a.false_alarms_on_obstacle_free, a.obstacle_free_frames)},
                    {"instances_found", per(a.instances_found, r.instances)},
                    {"found_iou25", per(a.found_iou25, r.instances)},
                    {"found_iou50", per(a.found_iou50, r.instances)},
                    {"components", ComponentsToJson(a.components)},
                    {"calibration_flat", r.calibration_flat}};
  j["obstacle_sweep"] = ObstacleListSweepToJson(r.list_sweep, r.instances, r.frames);
  // SMIYC component metrics of the served map (BP+Fusion@4) at the split's best pixel F1.
  j["components"] = nullptr;
  if (const auto c = r.components.find(kServedMapVariant); c != r.components.end())
    j["components"] = MapComponentsToJson(c->second);
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
        {"fpr_at_tpr95", NumberOrNull(r.fpr_at_tpr95.at(kCalibratedMapVariant))},
        {"components", r.components.count(kCalibratedMapVariant)
                           ? MapComponentsToJson(r.components.at(kCalibratedMapVariant))
                           : nlohmann::json()}};
  }
  j["timing_ms"] = nlohmann::json::object();
  for (const auto& [stage, ms] : r.stage_median_ms) j["timing_ms"][stage] = ms;
  return j;
}

namespace {

// What was evaluated, how the maps and regressors were set, and the reported obstacles.
void FormatEvalSummary(const EvalReport& r, std::ostringstream& o) {
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
  const ReportedObstacleCounts& a = r.reported;
  const auto share = [](int count, int of) { return of ? static_cast<double>(count) / of : 0.0; };
  char text[512];
  std::snprintf(text, sizeof text,
                "reported obstacles (score >= %.2f): %.2f false alarms per frame, %.2f per "
                "obstacle-free frame (%d such frames); instances found %.2f at box IoU >= 0.5, "
                "%.2f at >= 0.25, %.2f overlapped\n",
                DetectOptions{}.min_obstacle_score, share(a.false_alarms, r.frames),
                share(a.false_alarms_on_obstacle_free, a.obstacle_free_frames),
                a.obstacle_free_frames, share(a.found_iou50, r.instances),
                share(a.found_iou25, r.instances), share(a.instances_found, r.instances));
  o << text;
  if (r.calibration_flat)
    o << "obstacle calibration is flat: on its training frames the fused scores did not rank "
         "obstacles first, so every obstacle scores alike (retrain on more frames)\n";
  for (const SkippedFrame& f : r.skipped)
    o << "skipped frame " << f.frame << ": " << f.reason << "\n";
}

// One row of an average-recall table: the variant, then AR at each of kTableN.
void FormatRecallRow(const std::string& name, const VariantCurves& c, std::ostringstream& o) {
  char line[256];
  std::snprintf(line, sizeof line, "%-16s", name.c_str());
  o << line;
  for (int n : kTableN)
    o << " " << std::string(7 - Fixed(c.ar_table.at(n)).size(), ' ') << Fixed(c.ar_table.at(n));
  o << "\n";
}

// TPR at the table's FPRs, then AP and FPR at 95 % TPR, per pixel map variant.
void FormatPixelTables(const EvalReport& r, std::ostringstream& o) {
  char line[256];
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
}

// SMIYC's component metrics: each map at its best-F1 threshold, then the reported obstacles.
void FormatComponentTable(const EvalReport& r, std::ostringstream& o) {
  o << "\nComponent metrics (SegmentMeIfYouCan obstacle track)\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-22s %9s %6s %6s %6s %6s %6s %6s\n", "prediction", "threshold",
                "GT", "pred", "sIoU", "PPV", "F1", "F1@0.5");
  o << line;
  const auto defined = [](double v) { return std::isnan(v) ? std::string("n/a") : Fixed(v); };
  const auto row = [&](const std::string& name, const std::string& threshold,
                       const ComponentSummary& c) {
    std::snprintf(line, sizeof line, "%-22s %9s %6d %6d %6s %6s %6s %6s\n", name.c_str(),
                  threshold.c_str(), c.truth_components, c.predicted_components,
                  defined(c.mean_siou).c_str(), defined(c.mean_ppv).c_str(),
                  defined(c.mean_f1).c_str(), defined(c.f1_at_050).c_str());
    o << line;
  };
  for (const auto& [variant, c] : r.components) {
    if (c.level < 0) {
      o << variant << ": no obstacle pixel, no threshold of best F1\n";
      continue;
    }
    row(variant, Fixed(c.level / 255.0), c.summary);
  }
  row("reported obstacles", "-", r.reported.components);
}

}  // namespace

std::string FormatEvalTables(const EvalReport& r) {
  std::ostringstream o;
  FormatEvalSummary(r, o);
  o << "\nAverage recall (proposals)\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-16s %7s %7s %7s %7s %7s\n", "variant", "200", "400", "600",
                "800", "1000");
  o << line;
  for (const auto& v : ProposalVariants()) FormatRecallRow(v, r.proposals.at(v), o);
  FormatPixelTables(r, o);
  FormatComponentTable(r, o);
  o << "\n" << FormatObstacleListSweep(r.list_sweep, r.instances, r.frames);
  o << "\nAverage recall (regressed, score > 0.25)\n";
  for (const auto& v : RegressionVariants()) FormatRecallRow(v, r.regression.at(v), o);
  o << "\nGeometry (" << EvalGeometryName(r.geometry) << "):";
  for (const auto& [source, frames] : r.geometry_sources) o << " " << source << " " << frames;
  o << " frames; median |shift| " << Fixed(r.median_abs_shift_rows, 1) << " rows\n";
  o << "\nMedian time per frame (ms)\n";
  for (const auto& [stage, ms] : r.stage_median_ms) {
    std::snprintf(line, sizeof line, "%-16s %9.1f\n", stage.c_str(), ms);
    o << line;
  }
  return o.str();
}

}  // namespace tod
