// The two faces of a FrameBenchReport (frame_bench.h): the tables `tod bench` prints and the JSON
// of --json, whose key names are the contract of issue 11.
#include <cstdio>
#include <sstream>

#include "core/evaluation/frame_bench.h"

namespace tod {
namespace {

std::string Fixed(double v, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// Right-aligned in `width` characters.
std::string Cell(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : std::string(width - text.size(), ' ') + text;
}

std::string Header(std::string first_column) {
  first_column.resize(16, ' ');
  return first_column + Cell("median", 12) + Cell("p90", 12) + Cell("max", 12) + "\n";
}

std::string Row(const std::string& name, const Spread& s, int digits) {
  std::string row = name;
  row.resize(16, ' ');
  return row + Cell(Fixed(s.median, digits), 12) + Cell(Fixed(s.p90, digits), 12) +
         Cell(Fixed(s.max, digits), 12) + "\n";
}

nlohmann::json SpreadJson(const Spread& s) {
  return {{"median", s.median}, {"p90", s.p90}, {"max", s.max}};
}

nlohmann::json RecordJson(const FrameBenchRecord& r) {
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [stage, ms] : r.stages_ms) stages[stage] = ms;
  return {{"frame", r.frame},
          {"width", r.width},
          {"height", r.height},
          {"stages_ms", std::move(stages)},
          {"opencv_edgeboxes_ms", r.edgeboxes_ms},
          {"opencv_edgeboxes_boxes", r.edgeboxes_boxes},
          {"windows_scored", r.windows_scored},
          {"windows_walked", r.windows_walked},
          {"edge_groups", r.edge_groups},
          {"edge_pixels", r.edge_pixels},
          {"proposals", r.proposals},
          {"degraded_stages", r.degraded_stages}};
}

int DegradedFrames(const FrameBenchReport& report) {
  int n = 0;
  for (const FrameBenchRecord& r : report.records) n += r.degraded_stages.empty() ? 0 : 1;
  return n;
}

}  // namespace

std::string FormatBenchReport(const FrameBenchReport& report) {
  std::ostringstream out;
  out << report.records.size() << " frames, model " << report.model << ", " << report.threads
      << (report.threads == 1 ? " thread" : " threads") << " (one frame per thread), "
      << report.threads_per_request << (report.threads_per_request == 1 ? " thread" : " threads")
      << " per request";
  if (!report.skipped.empty()) out << ", " << report.skipped.size() << " skipped";
  if (report.budget_ms > 0) {
    out << ", frame budget " << Fixed(report.budget_ms, 0) << " ms (" << DegradedFrames(report)
        << " frames degraded)";
  }
  out << "\n\n";
  out << Header("stage (ms)");
  for (const auto& [stage, spread] : report.stages_ms) out << Row(stage, spread, 1);
  out << "\n" << Header("per frame");
  for (const auto& [name, spread] : report.counters) out << Row(name, spread, 0);
  out << "\nOpenCV EdgeBoxes on the same base edge map over R1 (alpha 0.65, beta 0.75, 1000 "
         "boxes)\n"
      << Row("edgeboxes ms", report.edgeboxes_ms, 1)
      << "ratio EdgeBoxes / our proposals (medians): " << Fixed(report.edgeboxes_ratio, 2) << "x\n"
      << "peak RSS: " << Fixed(report.peak_rss_mb, 1) << " MB ("
      << (report.shared_heap ? "one heap for all threads" : "a heap per thread") << ")\n";
  for (const SkippedFrame& f : report.skipped)
    out << "skipped " << f.frame << ": " << f.reason << "\n";
  for (const FrameBenchRecord& r : report.records) {
    if (r.degraded_stages.empty()) continue;
    out << "degraded " << r.frame << ":";
    for (const std::string& stage : r.degraded_stages) out << " " << stage;
    out << "\n";
  }
  return out.str();
}

nlohmann::json BenchReportToJson(const FrameBenchReport& report) {
  nlohmann::json j;
  j["frames"] = report.records.size();
  j["model"] = report.model;
  j["threads"] = report.threads;
  j["threads_per_request"] = report.threads_per_request;
  j["frame_budget_ms"] = report.budget_ms;
  j["degraded_frames"] = DegradedFrames(report);
  nlohmann::json stages = nlohmann::json::object();
  double proposals_median = 0;
  for (const auto& [stage, spread] : report.stages_ms) {
    stages[stage] = SpreadJson(spread);
    if (stage == "proposals") proposals_median = spread.median;
  }
  j["stages_ms"] = std::move(stages);
  j["proposals_ms"] = {{"median", proposals_median}};
  j["opencv_edgeboxes_ms"] = SpreadJson(report.edgeboxes_ms);
  j["edgeboxes_ratio"] = report.edgeboxes_ratio;
  j["peak_rss_mb"] = report.peak_rss_mb;
  j["shared_heap"] = report.shared_heap;
  nlohmann::json counters = nlohmann::json::object();
  for (const auto& [name, spread] : report.counters) counters[name] = SpreadJson(spread);
  j["counters"] = std::move(counters);
  j["skipped_frames"] = SkippedFramesToJson(report.skipped);
  j["per_frame"] = nlohmann::json::array();
  for (const FrameBenchRecord& r : report.records) j["per_frame"].push_back(RecordJson(r));
  return j;
}

}  // namespace tod
