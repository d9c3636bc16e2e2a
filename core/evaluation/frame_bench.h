// `tod bench` (issue 11): the real detector's time per stage on a directory of frames, with the
// work counters that explain it and OpenCV's Edge Boxes on the same base edge map as a yardstick.
//
// Per frame the file's bytes are read from disk first (not timed); then `decode` (cv::imdecode),
// the detector's own stages as ObstacleDetector::Detect times them (edges, superpixels,
// occlusion, proposals, features, regression, and probability_map reported as `map`), and
// `encode_map` (the 8-bit map encoded as PNG, as `tod detect` writes it). `total` is the wall
// clock from the start of decode to the end of encode_map, so it also holds the little the
// detector does between its timed stages.
//
// The counters (windows scored, edge groups, edge pixels, proposals) are the timed call's own
// (its FrameTrace), and the Edge Boxes baseline runs after it, untimed by the frame's stages, on
// the base edge map that call computed.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/datasets/bad_frames.h"
#include "core/pipeline/detector.h"

namespace tod {

class ObstacleDetector;

// The stage names of the contract, in pipeline order; `total` last.
const std::vector<std::string>& BenchStageNames();

// Every PNG, JPEG or WebP file under `dir` (recursively, extension case-insensitive), sorted by
// path so that --limit and the order of the records are the same from run to run.
Result<std::vector<std::string>> ListBenchFrames(const std::string& dir);

struct BenchOptions {
  int threads = 1;      // frames measured in parallel; 1 = one core, one frame at a time
  bool warm_up = true;  // one untimed run of the first frame before any measurement
  // Passed to every Detect call; its budget_ms (--frame-budget-ms) counts from the start of
  // decoding, as in the server.
  DetectOptions detect;
  std::function<void(const std::string&)> progress;  // one line per measured frame; may be empty
};

struct FrameBenchRecord {
  std::string frame;
  int width = 0;
  int height = 0;
  StageTimes stages_ms;  // BenchStageNames() order, then any stage the detector adds later
  double edgeboxes_ms = 0;
  long long edgeboxes_boxes = 0;
  long long windows_scored = 0;  // summed over the regions; set by the geometry alone
  long long windows_walked = 0;  // of those, past the early exit: grows with the edge density
  long long edge_groups = 0;
  long long edge_pixels = 0;
  long long proposals = 0;  // after the cross-region merge: what the features and regressors see
  std::vector<std::string> degraded_stages;  // what the frame budget cut short (timed run)
};

struct Spread {
  double median = 0;
  double p90 = 0;  // nearest rank: the smallest value with at least 90 % of the frames at or below
  double max = 0;
};
Spread SpreadOf(std::vector<double> values);

struct FrameBenchReport {
  std::string model;
  int threads = 1;              // frames measured side by side
  int threads_per_request = 1;  // DetectOptions::threads of every frame (--threads-per-request)
  double budget_ms = 0;         // DetectOptions::budget_ms of the run (0: none)
  std::vector<FrameBenchRecord> records;  // the frames measured, in path order
  std::vector<SkippedFrame> skipped;      // frames that could not be decoded or detected
  std::vector<std::pair<std::string, Spread>> stages_ms;  // as FrameBenchRecord::stages_ms
  Spread edgeboxes_ms;
  std::vector<std::pair<std::string, Spread>> counters;  // windows_scored, edge_groups, ...
  // OpenCV Edge Boxes median / our proposals median (> 1: ours is faster).
  double edgeboxes_ratio = 0;
  double peak_rss_mb = 0;    // of the whole process, after the run
  bool shared_heap = false;  // every thread allocated from one heap (HeapArenaShared)
};

// Measures every frame (skipping, and listing, those that fail). Fails only when no frame could
// be measured.
Result<FrameBenchReport> RunFrameBench(const ObstacleDetector& detector,
                                       const std::vector<std::string>& frames,
                                       const BenchOptions& options);

// The tables a person reads: per stage median / p90 / max, the counters, Edge Boxes and its
// ratio, peak RSS.
std::string FormatBenchReport(const FrameBenchReport& report);

// {"frames": n, "stages_ms": {STAGE: {"median","p90","max"}}, "proposals_ms": {"median"},
//  "opencv_edgeboxes_ms": {"median","p90","max"}, "edgeboxes_ratio", "peak_rss_mb", "shared_heap",
//  "counters": {NAME: {"median","p90","max"}}, "skipped_frames", "per_frame": [...]}
nlohmann::json BenchReportToJson(const FrameBenchReport& report);

}  // namespace tod
