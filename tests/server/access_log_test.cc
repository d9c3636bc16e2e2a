// The access-log line both front ends write per detection request (server/access_log.h): its
// fields (the same as the two hand-written lines it replaced), its level, and its count.
#include "server/access_log.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <memory>
#include <sstream>

#include "server/logging.h"

namespace tod::server {
namespace {

AccessRecord GrpcFrame() {
  AccessRecord access;
  access.event = "detect";
  access.protocol = "grpc";
  access.id = "g1";
  access.frame = "cam0/000001";
  access.peer = "ipv4:127.0.0.1:5000";
  access.bytes = 123;
  access.status = "OK";
  access.code = "OK";
  access.ms = 2.5;
  return access;
}

AccessRecord RestRequest() {
  AccessRecord access;
  access.event = "probability-map";
  access.protocol = "http";
  access.id = "h7";
  access.path = "/v1/probability-map";
  access.frame = "h7";
  access.peer = "127.0.0.1:6000";
  access.bytes = 9;
  access.status = 413u;
  access.code = "RESOURCE_EXHAUSTED";
  access.ms = 0.5;
  access.error = "image: too large";
  return access;
}

TEST(AccessLogTest, GrpcFieldsAreTheOnesTheServiceAlwaysLogged) {
  const nlohmann::json expected = {{"id", "g1"},
                                   {"protocol", "grpc"},
                                   {"frame", "cam0/000001"},
                                   {"peer", "ipv4:127.0.0.1:5000"},
                                   {"bytes", 123},
                                   {"status", "OK"},
                                   {"ms", 2.5}};
  EXPECT_EQ(AccessLogFields(GrpcFrame()), expected);
  AccessRecord cancelled = GrpcFrame();
  cancelled.status = "CANCELLED";
  cancelled.error = "stopped";
  cancelled.cancelled = "client_cancelled";
  const nlohmann::json fields = AccessLogFields(cancelled);
  EXPECT_EQ(fields["error"], "stopped");
  EXPECT_EQ(fields["cancelled"], "client_cancelled");
  EXPECT_FALSE(fields.contains("path"));
}

TEST(AccessLogTest, RestFieldsCarryThePathAndTheHttpStatus) {
  const nlohmann::json expected = {{"id", "h7"},
                                   {"protocol", "http"},
                                   {"path", "/v1/probability-map"},
                                   {"frame", "h7"},
                                   {"peer", "127.0.0.1:6000"},
                                   {"bytes", 9},
                                   {"status", 413},
                                   {"ms", 0.5},
                                   {"error", "image: too large"}};
  EXPECT_EQ(AccessLogFields(RestRequest()), expected);
  EXPECT_EQ(AccessLogFields(RestRequest()).dump(), expected.dump());  // 413, not "413"
}

class AccessLogLineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(SetUpLogging("text", "info").ok());
    previous_ = spdlog::default_logger();
    auto logger = std::make_shared<spdlog::logger>(
        "access_log_test", std::make_shared<spdlog::sinks::ostream_sink_st>(stream_));
    logger->set_pattern("%l %v");
    spdlog::set_default_logger(logger);
  }
  void TearDown() override { spdlog::set_default_logger(previous_); }

  std::ostringstream stream_;
  std::shared_ptr<spdlog::logger> previous_;
};

TEST_F(AccessLogLineTest, LogsOneLineAndCountsTheRequest) {
  ServerMetrics metrics;
  LogAccess(GrpcFrame(), metrics);
  EXPECT_EQ(stream_.str(),
            "info detect bytes=123 frame=cam0/000001 id=g1 ms=2.5 peer=ipv4:127.0.0.1:5000 "
            "protocol=grpc status=OK\n");
  const std::string text = metrics.SerializeText();
  EXPECT_NE(text.find("tod_requests_total{code=\"OK\",protocol=\"grpc\"} 1"), std::string::npos)
      << text;
  EXPECT_NE(text.find("tod_request_duration_seconds_sum{protocol=\"grpc\"} 0.0025"),
            std::string::npos)
      << text;
}

TEST_F(AccessLogLineTest, AnErrorMakesTheLineAWarning) {
  ServerMetrics metrics;
  LogAccess(RestRequest(), metrics);
  EXPECT_EQ(stream_.str(),
            "warning probability-map bytes=9 error=\"image: too large\" frame=h7 id=h7 ms=0.5 "
            "path=/v1/probability-map peer=127.0.0.1:6000 protocol=http status=413\n");
  EXPECT_NE(metrics.SerializeText().find(
                "tod_requests_total{code=\"RESOURCE_EXHAUSTED\",protocol=\"http\"} 1"),
            std::string::npos);
}

}  // namespace
}  // namespace tod::server
