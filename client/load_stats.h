// Load-test bookkeeping: latencies and status codes in, throughput / percentiles / counts out.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace tod::client {

struct LoadSample {
  double latency_ms = 0;
  std::string code;  // "OK" / gRPC code name, or the HTTP status ("200", "503", ...)
  bool ok = false;
};

struct LatencySummary {
  double p50 = 0, p90 = 0, p99 = 0, max = 0, mean = 0;
};

struct LoadReport {
  std::string protocol;  // "grpc" | "http"
  std::string mode;      // "closed" | "open"
  int concurrency = 0;
  double rate = 0;        // open loop: scheduled requests per second
  double duration_s = 0;  // measured window (after warm-up)
  long long requests = 0;
  long long succeeded = 0;
  double throughput_rps = 0;     // responses per second (any status)
  double ok_throughput_rps = 0;  // successful responses per second
  LatencySummary latency_ms;     // over successful requests
  std::map<std::string, long long> codes;
};

// Nearest-rank percentile (q in [0, 1]) of values sorted ascending; 0 for no values.
double Percentile(const std::vector<double>& sorted, double q);

LoadReport Summarize(const std::vector<LoadSample>& samples, double duration_s);

std::string FormatTable(const LoadReport& report);
nlohmann::json ReportToJson(const LoadReport& report);

}  // namespace tod::client
