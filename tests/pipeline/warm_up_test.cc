#include "core/pipeline/warm_up.h"

#include <gtest/gtest.h>

#include <memory>

#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

// Records what the warm-up asks for and answers with a fixed status.
class RecordingDetector : public Detector {
 public:
  explicit RecordingDetector(Status answer) : answer_(std::move(answer)) {}
  Result<Detection> Detect(const cv::Mat3b& bgr, const DetectOptions& options) const override {
    ++calls;
    frame_size = bgr.size();
    budget_ms = options.budget_ms;
    if (!answer_.ok()) return answer_;
    return Detection{};
  }
  const ModelInfo& info() const override { return info_; }

  mutable int calls = 0;
  mutable cv::Size frame_size;
  mutable double budget_ms = -1;

 private:
  Status answer_;
  ModelInfo info_;
};

TEST(WarmUpTest, RunsOneUnbudgetedDetectionOnTheMadeUpFrame) {
  const RecordingDetector detector(Status::Ok());
  const Result<double> ms = WarmUp(detector, {.width = 320, .height = 160});
  ASSERT_TRUE(ms.ok()) << ms.status().ToString();
  EXPECT_GE(*ms, 0.0);
  EXPECT_EQ(detector.calls, 1);
  EXPECT_EQ(detector.frame_size, cv::Size(320, 160));
  EXPECT_EQ(detector.budget_ms, 0.0);  // no budget: every stage runs
}

TEST(WarmUpTest, ADetectorThatFailsOnTheMadeUpFrameIsAnErrorNamingTheWarmUp) {
  const RecordingDetector detector(Status::Internal("forest walk broke"));
  const Result<double> ms = WarmUp(detector);
  ASSERT_FALSE(ms.ok());
  EXPECT_NE(ms.status().message().find("warm-up"), std::string::npos) << ms.status().ToString();
  EXPECT_NE(ms.status().message().find("forest walk broke"), std::string::npos);
}

TEST(WarmUpTest, TheFrameIsDeterministicTexturedAndHasDarkBlocks) {
  const cv::Mat3b a = WarmUpFrame({});
  const cv::Mat3b b = WarmUpFrame({});
  ASSERT_EQ(a.size(), cv::Size(512, 256));
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  cv::Mat1b grey;
  cv::cvtColor(a, grey, cv::COLOR_BGR2GRAY);
  double lo = 0, hi = 0;
  cv::minMaxLoc(grey, &lo, &hi);
  EXPECT_LT(lo, 60);   // the blocks
  EXPECT_GT(hi, 150);  // the bright top of the ramp
}

TEST(WarmUpTest, AWholePipelineWarmsUpOnItsFrame) {
  const ObstacleDetector detector(TinyBundle(), "tiny");
  const Result<double> ms = WarmUp(detector);
  ASSERT_TRUE(ms.ok()) << ms.status().ToString();
  EXPECT_GT(*ms, 0.0);
}

}  // namespace
}  // namespace tod
