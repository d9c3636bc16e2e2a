#include "client/load_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

namespace tod::client {

double Percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  const double clamped = std::clamp(q, 0.0, 1.0);
  // Nearest rank: the smallest value with at least q of the values at or below it.
  const size_t rank = static_cast<size_t>(std::ceil(clamped * static_cast<double>(sorted.size())));
  return sorted[rank == 0 ? 0 : rank - 1];
}

LoadReport Summarize(const std::vector<LoadSample>& samples, double duration_s) {
  LoadReport report;
  report.duration_s = duration_s;
  std::vector<double> latencies;
  for (const LoadSample& sample : samples) {
    ++report.requests;
    ++report.codes[sample.code];
    if (sample.ok) {
      ++report.succeeded;
      latencies.push_back(sample.latency_ms);
    }
  }
  std::sort(latencies.begin(), latencies.end());
  if (!latencies.empty()) {
    report.latency_ms.p50 = Percentile(latencies, 0.50);
    report.latency_ms.p90 = Percentile(latencies, 0.90);
    report.latency_ms.p99 = Percentile(latencies, 0.99);
    report.latency_ms.max = latencies.back();
    report.latency_ms.mean = std::accumulate(latencies.begin(), latencies.end(), 0.0) /
                             static_cast<double>(latencies.size());
  }
  if (duration_s > 0) {
    report.throughput_rps = static_cast<double>(report.requests) / duration_s;
    report.ok_throughput_rps = static_cast<double>(report.succeeded) / duration_s;
  }
  return report;
}

std::string FormatTable(const LoadReport& report) {
  char line[256];
  std::string out;
  std::snprintf(line, sizeof(line), "%-22s %s, %s loop, concurrency %d%s\n", "load",
                report.protocol.c_str(), report.mode.c_str(), report.concurrency,
                report.mode == "open"
                    ? (std::string(", rate ") + std::to_string(report.rate) + "/s").c_str()
                    : "");
  out += line;
  std::snprintf(line, sizeof(line), "%-22s %.2f s\n", "measured", report.duration_s);
  out += line;
  std::snprintf(line, sizeof(line), "%-22s %lld (%lld ok)\n", "requests", report.requests,
                report.succeeded);
  out += line;
  std::snprintf(line, sizeof(line), "%-22s %.2f req/s (%.2f ok/s)\n", "throughput",
                report.throughput_rps, report.ok_throughput_rps);
  out += line;
  std::snprintf(line, sizeof(line), "%-22s %10s %10s %10s %10s %10s\n", "latency ms (ok)", "p50",
                "p90", "p99", "max", "mean");
  out += line;
  std::snprintf(line, sizeof(line), "%-22s %10.2f %10.2f %10.2f %10.2f %10.2f\n", "",
                report.latency_ms.p50, report.latency_ms.p90, report.latency_ms.p99,
                report.latency_ms.max, report.latency_ms.mean);
  out += line;
  for (const auto& [code, count] : report.codes) {
    std::snprintf(line, sizeof(line), "%-22s %lld\n", ("status " + code).c_str(), count);
    out += line;
  }
  return out;
}

nlohmann::json ReportToJson(const LoadReport& report) {
  nlohmann::json codes = nlohmann::json::object();
  for (const auto& [code, count] : report.codes) codes[code] = count;
  return {{"protocol", report.protocol},
          {"mode", report.mode},
          {"concurrency", report.concurrency},
          {"rate", report.rate},
          {"duration_s", report.duration_s},
          {"requests", report.requests},
          {"succeeded", report.succeeded},
          {"throughput_rps", report.throughput_rps},
          {"ok_throughput_rps", report.ok_throughput_rps},
          {"latency_ms",
           {{"p50", report.latency_ms.p50},
            {"p90", report.latency_ms.p90},
            {"p99", report.latency_ms.p99},
            {"max", report.latency_ms.max},
            {"mean", report.latency_ms.mean}}},
          {"codes", codes}};
}

}  // namespace tod::client
