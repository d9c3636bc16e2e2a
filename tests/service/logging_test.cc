// The text log format keeps one request per line whatever the client sent (a regression input of
// fuzz_rest_request, docs/service.md#found-and-fixed: a frame_id of "a%0Ab" used to split the
// request's log line).
#include "server/logging.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <memory>
#include <sstream>

namespace tod::server {
namespace {

class TextLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(SetUpLogging("text", "info").ok());
    previous_ = spdlog::default_logger();
    auto logger = std::make_shared<spdlog::logger>(
        "text_log_test", std::make_shared<spdlog::sinks::ostream_sink_st>(stream_));
    logger->set_pattern("%v");
    spdlog::set_default_logger(logger);
  }
  void TearDown() override { spdlog::set_default_logger(previous_); }

  std::ostringstream stream_;
  std::shared_ptr<spdlog::logger> previous_;
};

TEST_F(TextLogTest, ControlCharactersInAValueAreEscapedNotWritten) {
  LogEvent(spdlog::level::info, "detect",
           {{"frame", "a\n2030-01-01T00:00:00.000000Z\tinfo\tdetect\tid=h9"},
            {"path", "/v1/detect\r"},
            {"peer", "tab\there"}});
  const std::string line = stream_.str();
  ASSERT_FALSE(line.empty());
  EXPECT_EQ(line.find('\n'), line.size() - 1) << line;  // one line
  EXPECT_EQ(line.find('\r'), std::string::npos) << line;
  EXPECT_EQ(line.find('\t'), std::string::npos) << line;
  EXPECT_NE(line.find(R"(frame="a\n2030)"), std::string::npos) << line;
}

TEST_F(TextLogTest, PlainValuesStayUnquoted) {
  LogEvent(spdlog::level::info, "detect", {{"frame", "cam0/000001"}, {"status", "OK"}});
  EXPECT_EQ(stream_.str(), "detect frame=cam0/000001 status=OK\n");
}

}  // namespace
}  // namespace tod::server
