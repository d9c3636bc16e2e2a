#include "core/evaluation/frame_bench.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <opencv2/imgcodecs.hpp>

#include "core/base/memory_usage.h"
#include "core/data/image_file.h"
#include "core/evaluation/edge_boxes_baseline.h"
#include "core/pipeline/detection_output.h"
#include "core/pipeline/frame_budget.h"
#include "core/pipeline/frame_geometry.h"
#include "core/pipeline/frame_stages.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/parallel.h"

namespace tod {
namespace {

using Clock = std::chrono::steady_clock;

double MsBetween(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

constexpr int kEdgeBoxesMax = 1000;      // the baseline: 1000 boxes
constexpr std::size_t kStageSlots = 16;  // a record's stages: the contract's and room for more

bool IsFrameFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".webp";
}

// The detector's stage names mapped onto the contract's (only probability_map differs).
std::string ContractName(const std::string& detector_stage) {
  return detector_stage == "probability_map" ? "map" : detector_stage;
}

// The work counters of the timed call's own stages (its trace), and the Edge Boxes baseline
// on the base edges those stages computed.
void CountWork(const FrameTrace& trace, FrameBenchRecord& record) {
  for (const EdgeBoxStats& stats : trace.regions.stats) {
    record.windows_scored += stats.windows_visited;
    record.windows_walked += stats.windows_past_early_exit;
    record.edge_groups += stats.edge_groups;
    record.edge_pixels += stats.edge_pixels;
  }
  record.proposals =
      static_cast<long long>(trace.regressed.proposals.boxes.size() + trace.regressed.dropped);

  // E is the same map with or without the obstacle-aware enhancement, so the baseline scores
  // exactly the base edges our proposals start from. Its time includes the orientation and the
  // edge thinning it needs (edge_boxes_baseline.h), not the edge map itself.
  const Clock::time_point start = Clock::now();
  const std::vector<Box> boxes =
      EdgeBoxesBaseline(trace.oaocc.base_edge, trace.oaocc.r1, kEdgeBoxesMax);
  record.edgeboxes_ms = MsBetween(start, Clock::now());
  record.edgeboxes_boxes = static_cast<long long>(boxes.size());
}

// The timed part: decode, the detector's call as `tod detect` makes it, and the map encoded as
// `tod detect` writes it. The call's trace is handed back for the counters (keeping it costs the
// call nothing: it holds what the stages made anyway); the detection is released here.
Result<FrameBenchRecord> TimeFrame(const ObstacleDetector& detector, const std::string& bytes,
                                   const DetectOptions& options, FrameTrace& trace) {
  const Clock::time_point start = Clock::now();
  Result<cv::Mat3b> decoded = DecodeColourImage(bytes);
  const Clock::time_point decoded_at = Clock::now();
  if (!decoded.ok()) return decoded.status();
  const cv::Mat3b bgr = std::move(decoded).value();
  // The frame budget counts from the start of decoding, as the server counts it.
  DetectOptions detect = options;
  detect.budget_ms = BudgetLeftMs(detect.budget_ms, MsBetween(start, decoded_at));
  const auto detection = detector.Detect(bgr, detect, &trace);
  if (!detection.ok()) return detection.status();
  const Clock::time_point encode_start = Clock::now();
  std::vector<uchar> png;
  const bool encoded = cv::imencode(".png", ProbabilityTo8Bit(detection->probability), png);
  const Clock::time_point end = Clock::now();
  if (!encoded) return Status::Internal("cannot encode the probability map");

  FrameBenchRecord record;
  record.width = bgr.cols;
  record.height = bgr.rows;
  record.stages_ms.emplace_back("decode", MsBetween(start, decoded_at));
  for (const auto& [stage, ms] : detection->timings)
    record.stages_ms.emplace_back(ContractName(stage), ms);
  record.stages_ms.emplace_back("encode_map", MsBetween(encode_start, end));
  record.stages_ms.emplace_back("total", MsBetween(start, end));
  record.degraded_stages = detection->degraded_stages;
  return record;
}

Result<FrameBenchRecord> MeasureFrame(const ObstacleDetector& detector, const std::string& path,
                                      const DetectOptions& options) {
  // Reading the file is the storage's time, not ours: done before the clock starts.
  const Result<std::string> bytes = ReadFileBytes(path);
  if (!bytes.ok()) return bytes.status();
  FrameTrace trace;
  auto record = TimeFrame(detector, *bytes, options, trace);
  if (!record.ok()) return record.status();
  record->frame = path;
  CountWork(trace, *record);
  return record;
}

// Every frame's record, allocated before any frame runs. A record kept from each frame (its path,
// its stage times) would otherwise be allocated in the middle of the heap that frame's large
// tables have just freed, where it stays: one shared heap that keeps freed blocks
// (heap_tuning.h) could then not join those blocks again, and grew by about 12 MB a frame for
// the rest of the run (`tod bench` over the 50 dev frames: 948 MB peak RSS against 201 MB, with
// 131 MB live at most; docs/findings.md#the-benchs-heap).
std::vector<FrameBenchRecord> RecordSlots(const std::vector<std::string>& frames) {
  std::vector<FrameBenchRecord> slots(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    slots[i].frame = frames[i];
    slots[i].stages_ms.reserve(kStageSlots);
  }
  return slots;
}

// The contract's stages in its order, then any stage the detector adds later (in pipeline order),
// total last. A contract stage no record has (a renamed detector stage) is left out rather than
// reported as 0 ms, so the JSON misses its key and the CLI test says so.
std::vector<std::string> StageOrder(const std::vector<FrameBenchRecord>& records) {
  const auto recorded = [&](const std::string& stage) {
    for (const FrameBenchRecord& r : records)
      for (const auto& [name, ms] : r.stages_ms)
        if (name == stage) return true;
    return false;
  };
  const std::vector<std::string>& contract = BenchStageNames();
  const auto in_contract = [&](const std::string& stage) {
    return std::find(contract.begin(), contract.end(), stage) != contract.end();
  };
  std::vector<std::string> order;
  for (const std::string& stage : contract)
    if (stage != "total" && recorded(stage)) order.push_back(stage);
  for (const FrameBenchRecord& r : records)
    for (const auto& [stage, ms] : r.stages_ms)
      if (!in_contract(stage) && std::find(order.begin(), order.end(), stage) == order.end())
        order.push_back(stage);
  order.push_back("total");
  return order;
}

}  // namespace

const std::vector<std::string>& BenchStageNames() {
  static const std::vector<std::string> kNames = {
      "decode",     "calibration", "edges", "superpixels", "occlusion", "proposals",
      "features",   "regression",  "map",   "encode_map",  "total"};
  return kNames;
}

Result<std::vector<std::string>> ListBenchFrames(const std::string& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return Status::NotFound("no directory " + dir);
  std::vector<std::string> frames;
  for (auto it = std::filesystem::recursive_directory_iterator(dir, ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec) && IsFrameFile(it->path())) frames.push_back(it->path().string());
  if (ec) return Status::NotFound("cannot list " + dir + ": " + ec.message());
  std::sort(frames.begin(), frames.end());
  return frames;
}

Spread SpreadOf(std::vector<double> values) {
  Spread s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  s.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  const auto rank = static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(n)));
  s.p90 = values[std::clamp<std::size_t>(rank, 1, n) - 1];
  s.max = values.back();
  return s;
}

Result<FrameBenchReport> RunFrameBench(const ObstacleDetector& detector,
                                       const std::vector<std::string>& frames,
                                       const BenchOptions& options) {
  if (frames.empty()) return Status::InvalidArgument("no frames to measure");
  DetectOptions detect = options.detect;
  detect.want_probability_map = true;  // encode_map is part of every frame
  // Before the first frame: the records' storage then lies below every frame's tables.
  std::vector<FrameBenchRecord> measured = RecordSlots(frames);
  // The first frame pays for faulting in the heap, the model's pages and OpenCV's lazy setup;
  // its numbers would describe a cold process, not a running service.
  if (options.warm_up) (void)MeasureFrame(detector, frames.front(), detect);

  const int n = static_cast<int>(frames.size());
  std::mutex progress_mutex;
  int done = 0;
  const std::vector<Status> per_frame = ParallelFor(n, options.threads, [&](int i) -> Status {
    const auto record = MeasureFrame(detector, frames[i], detect);
    if (!record.ok()) return record.status();
    // Copy-assigned, not moved: the slot's path and stage list keep their storage (the same path,
    // at most kStageSlots stages with names short enough to live inside std::string).
    measured[i] = *record;
    if (options.progress) {
      std::lock_guard lock(progress_mutex);
      const double total = measured[i].stages_ms.back().second;
      options.progress("frame " + std::to_string(++done) + "/" + std::to_string(n) + " " +
                       frames[i] + ": " + std::to_string(std::lround(total)) + " ms");
    }
    return Status::Ok();
  });

  FrameBenchReport report;
  report.model = detector.info().name;
  report.threads = options.threads;
  report.threads_per_request = options.detect.threads;
  report.budget_ms = options.detect.budget_ms;
  const Status bad = ApplyBadFramePolicy(
      per_frame, [&](int i) { return frames[i]; }, BadFramePolicy::kSkip, &report.skipped);
  if (!bad.ok()) return bad;
  report.records.reserve(measured.size());
  for (int i = 0; i < n; ++i)
    if (per_frame[i].ok()) report.records.push_back(std::move(measured[i]));
  if (report.records.empty())
    return Status::InvalidArgument(
        "no frame could be measured (first: " + report.skipped.front().frame + ": " +
        report.skipped.front().reason + ")");

  for (const std::string& stage : StageOrder(report.records)) {
    std::vector<double> values;
    for (const FrameBenchRecord& r : report.records)
      for (const auto& [name, ms] : r.stages_ms)
        if (name == stage) values.push_back(ms);
    report.stages_ms.emplace_back(stage, SpreadOf(std::move(values)));
  }
  std::vector<double> edgeboxes;
  for (const FrameBenchRecord& r : report.records) edgeboxes.push_back(r.edgeboxes_ms);
  report.edgeboxes_ms = SpreadOf(std::move(edgeboxes));
  const std::vector<std::pair<std::string, long long FrameBenchRecord::*>> counters = {
      {"windows_scored", &FrameBenchRecord::windows_scored},
      {"windows_walked", &FrameBenchRecord::windows_walked},
      {"edge_groups", &FrameBenchRecord::edge_groups},
      {"edge_pixels", &FrameBenchRecord::edge_pixels},
      {"proposals", &FrameBenchRecord::proposals}};
  for (const auto& [name, field] : counters) {
    std::vector<double> values;
    for (const FrameBenchRecord& r : report.records)
      values.push_back(static_cast<double>(r.*field));
    report.counters.emplace_back(name, SpreadOf(std::move(values)));
  }
  for (const auto& [stage, spread] : report.stages_ms)
    if (stage == "proposals" && spread.median > 0)
      report.edgeboxes_ratio = report.edgeboxes_ms.median / spread.median;
  report.peak_rss_mb = PeakRssMb();
  return report;
}

}  // namespace tod
