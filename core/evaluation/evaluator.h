// `tod eval`: the paper's two tables on a dataset split (ALGORITHM.md §8) for the variants
//   proposals:  EB, OLP@1, OAOCC+OLP@1, OAOCC+OLP@4, OAOCC+OLP@4+MS   (average recall)
//   regression: OP+ORDR@4, BP+ORDR@4, BP+Fusion@4   (TPR at FPR, average recall)
// and, for the regression variants, the anomaly-segmentation metrics (pixel AP, FPR at 95 % TPR)
// plus the median time of each stage per frame.
#pragma once

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/datasets/dataset_selection.h"
#include "core/evaluation/frame_evaluation.h"
#include "core/metrics/component_metrics.h"
#include "core/metrics/pixel_histogram_metrics.h"
#include "core/metrics/pixel_roc.h"
#include "core/pipeline/model_bundle.h"

namespace tod {

// Where the detector's road geometry comes from in an evaluation (self-calibration, issue 48).
enum class EvalGeometry {
  kFrame,   // each frame calibrated alone: what a request without camera_id gets
  kCamera,  // the split is one camera's frames: each stands on the camera's median over all
  kBundle,  // no calibration: the bundle's geometry
};
// "frame" / "camera" / "bundle"; ParseEvalGeometry is its inverse (nullopt for anything else).
const char* EvalGeometryName(EvalGeometry geometry);
std::optional<EvalGeometry> ParseEvalGeometry(const std::string& name);

struct EvalOptions {
  DatasetSelection data;  // the test split by default
  EvalGeometry geometry = EvalGeometry::kFrame;
  int threads = 0;
  std::function<void(const std::string&)> progress;
};

struct VariantCurves {
  std::vector<int> n_grid;             // 0, 5, ..., 1000
  std::vector<double> recall_at_07;    // recall vs N at IoU 0.7
  std::vector<double> iou_grid;        // 0.50 ... 1.00
  std::vector<double> recall_at_1000;  // recall vs IoU at N = 1000
  std::vector<double> average_recall;  // AR vs N
  std::map<int, double> ar_table;      // N = 200 ... 1000
};

// Obstacles as the detector reports them (calibrated score >= its default minimum), counted over
// the split: a false alarm is a reported obstacle without a ground-truth obstacle pixel.
struct ReportedObstacleCounts {
  int false_alarms = 0;
  int obstacle_free_frames = 0;
  int false_alarms_on_obstacle_free = 0;
  int instances_found = 0;      // ground-truth instances overlapped by a reported obstacle
  int found_iou25 = 0;          // ... matched by a reported box at box IoU >= 0.25
  int found_iou50 = 0;          // ... at box IoU >= 0.5
  ComponentSummary components;  // SMIYC components of the reported obstacles' pixels
};

// SMIYC's component metrics of one map variant, binarised at the split's best pixel F1.
struct MapComponents {
  int level = -1;  // the 8-bit threshold (v >= level); -1 without an obstacle pixel
  ComponentSummary summary;
};

struct EvalReport {
  int frames = 0;  // evaluated (skipped ones not counted)
  std::vector<SkippedFrame> skipped;
  ReportedObstacleCounts reported;
  // The obstacle list under other reporting rules (obstacle_list_sweep.h), summed over the split.
  std::map<std::string, ObstacleListCounts> list_sweep;
  // What the pixel metrics' negatives are: "road label" (LAF free space, MODDv2 water) or
  // "every non-void pixel that is not an obstacle" (mask benchmarks without a road label).
  std::string free_space;
  // The bundle's isolation exponent of the paper's map (box_isolation.h): the regression
  // variants' maps weigh each box by isolation^this; 0 is the paper's map as published.
  float map_isolation_exponent = 0.f;
  bool map_superpixel_shares = false;  // the paper's map weighs boxes by superpixel shares
  // The obstacle calibration was held flat in training (obstacle_calibration.h): every obstacle
  // scores the same, so the calibrated map is the superpixel shares alone and none is reported.
  bool calibration_flat = false;
  // The regressors' row width and which features they are (ProposalFeatureSet): the paper's 20,
  // with the vertical edge share and the road-surround feature when the bundle has them.
  int proposal_features = 0;
  std::string proposal_feature_set;
  int instances = 0;
  std::map<std::string, VariantCurves> proposals;   // proposal variants
  std::map<std::string, VariantCurves> regression;  // regression variants (ranked lists)
  std::map<std::string, RocCurve> roc;              // regression variants (+ kCalibratedMapVariant)
  std::map<std::string, std::map<double, double>> tpr_at_fpr;
  // On the served 8-bit map (core/metrics/pixel_histogram_metrics.h), regression variants:
  // NaN when undefined (no obstacle pixel; for FPR also no free-space pixel).
  std::map<std::string, double> average_precision;
  std::map<std::string, double> fpr_at_tpr95;
  std::map<std::string, PrecisionRecallCurve> precision_recall;
  // Per ComponentMapVariants(): the paper's served map and the calibrated map when evaluated.
  std::map<std::string, MapComponents> components;
  std::vector<std::pair<std::string, double>> stage_median_ms;  // detector stages + "total"
  // How the geometry was calibrated, and the frames that stood on each source (HorizonSource
  // names) with the median absolute shift of the bundle's rows, in rows.
  EvalGeometry geometry = EvalGeometry::kFrame;
  std::map<std::string, int> geometry_sources;
  double median_abs_shift_rows = 0;
};

Result<EvalReport> EvaluateModel(const ModelBundle& bundle, const EvalOptions& options);

// The variants with pixel metrics in `report`: RegressionVariants(), then kCalibratedMapVariant
// when it was evaluated.
std::vector<std::string> PixelMapVariants(const EvalReport& report);

// The map variants with component metrics: BP+Fusion@4 (the map `tod detect` serves by default)
// and kCalibratedMapVariant when it was evaluated.
std::vector<std::string> ComponentMapVariants(const EvalReport& report);

// The JSON of the issue: {"frames","instances","proposals":{V:{"ar":{...}}},
// "regression":{V:{"tpr_at_fpr":{...},"ar":{...},"ap":x,"fpr_at_tpr95":x}},
// "calibrated_map":{"boxes":"BP+Fusion@4","tpr_at_fpr":{...},"ap":x,"fpr_at_tpr95":x} (null
// without a fitted calibration),
// "timing_ms":{STAGE:x,...,"total":x}}; an undefined "ap" / "fpr_at_tpr95" is null.
nlohmann::json EvalReportToJson(const EvalReport& report);
// The two tables and the timing table as text.
std::string FormatEvalTables(const EvalReport& report);

}  // namespace tod
