// tod_load's statistics: nearest-rank percentiles, counts per code, throughput.
#include "client/load_stats.h"

#include <gtest/gtest.h>

namespace tod::client {
namespace {

TEST(LoadStatsTest, NearestRankPercentiles) {
  const std::vector<double> sorted = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  EXPECT_DOUBLE_EQ(Percentile(sorted, 0.5), 5);    // ceil(5) = rank 5
  EXPECT_DOUBLE_EQ(Percentile(sorted, 0.9), 9);    // ceil(9) = rank 9
  EXPECT_DOUBLE_EQ(Percentile(sorted, 0.99), 10);  // ceil(9.9) = rank 10
  EXPECT_DOUBLE_EQ(Percentile(sorted, 0.0), 1);
  EXPECT_DOUBLE_EQ(Percentile(sorted, 1.0), 10);
  EXPECT_DOUBLE_EQ(Percentile({}, 0.5), 0);
  EXPECT_DOUBLE_EQ(Percentile({42}, 0.99), 42);
}

TEST(LoadStatsTest, SummaryCountsCodesAndUsesSuccessfulLatencies) {
  std::vector<LoadSample> samples;
  for (int i = 1; i <= 4; ++i) samples.push_back({10.0 * i, "200", true});  // 10 20 30 40
  samples.push_back({1.0, "503", false});
  samples.push_back({2.0, "503", false});
  const LoadReport report = Summarize(samples, 2.0);
  EXPECT_EQ(report.requests, 6);
  EXPECT_EQ(report.succeeded, 4);
  EXPECT_EQ(report.codes.at("200"), 4);
  EXPECT_EQ(report.codes.at("503"), 2);
  EXPECT_DOUBLE_EQ(report.throughput_rps, 3.0);
  EXPECT_DOUBLE_EQ(report.ok_throughput_rps, 2.0);
  EXPECT_DOUBLE_EQ(report.latency_ms.p50, 20);
  EXPECT_DOUBLE_EQ(report.latency_ms.p90, 40);
  EXPECT_DOUBLE_EQ(report.latency_ms.max, 40);
  EXPECT_DOUBLE_EQ(report.latency_ms.mean, 25);
  const nlohmann::json json = ReportToJson(report);
  EXPECT_EQ(json["codes"]["503"], 2);
  EXPECT_DOUBLE_EQ(json["latency_ms"]["p99"].get<double>(), 40);
  const std::string table = FormatTable(report);
  EXPECT_NE(table.find("status 503"), std::string::npos);
  EXPECT_NE(table.find("p99"), std::string::npos);
}

}  // namespace
}  // namespace tod::client
