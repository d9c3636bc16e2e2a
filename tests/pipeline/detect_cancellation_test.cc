// DetectOptions::cancelled: Detect asks it at every stage boundary and stops with its Status.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <string>
#include <vector>

#include "core/pipeline/obstacle_detector.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

// The boundaries Detect asks at, in order (the bundle has an occlusion classifier).
const std::vector<std::string> kBoundaries = {"calibration", "edges",     "superpixels", "occlusion",
                                              "proposals", "features",    "regression"};

class DetectCancellationTest : public TinyDetectorTest {
 protected:
  const cv::Mat3b frame_ = RoadFrame(256, 128);
};

TEST_F(DetectCancellationTest, WithoutAHookEveryStageRuns) {
  const Result<Detection> detection = detector_->Detect(frame_, DetectOptions{});
  ASSERT_TRUE(detection.ok()) << detection.status().ToString();
  std::vector<std::string> stages;
  for (const auto& [stage, ms] : detection->timings) stages.push_back(stage);
  for (const std::string& boundary : kBoundaries) {
    EXPECT_NE(std::find(stages.begin(), stages.end(), boundary), stages.end()) << boundary;
  }
}

// The tiny bundle has no fitted calibration: asking for the calibrated map is refused before
// the first stage (the hook, asked at every boundary, is never asked).
TEST_F(DetectCancellationTest, AMapTheBundleCannotMakeIsRefusedBeforeAnyWork) {
  int asked = 0;
  DetectOptions options;
  options.map_kind = MapKind::kCalibrated;
  options.cancelled = [&asked] {
    ++asked;
    return Status::Ok();
  };
  const Result<Detection> detection = detector_->Detect(frame_, options);
  ASSERT_FALSE(detection.ok());
  EXPECT_EQ(detection.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(detection.status().message().find("calibration"), std::string::npos);
  EXPECT_EQ(asked, 0);
}

TEST_F(DetectCancellationTest, AnOkHookIsAskedAtEveryBoundaryAndChangesNothing) {
  int asked = 0;
  DetectOptions options;
  options.cancelled = [&asked] {
    ++asked;
    return Status::Ok();
  };
  const Result<Detection> with_hook = detector_->Detect(frame_, options);
  const Result<Detection> without = detector_->Detect(frame_, DetectOptions{});
  ASSERT_TRUE(with_hook.ok() && without.ok());
  // Every Mark asks: the six boundaries above plus the probability map at the end.
  EXPECT_GE(asked, static_cast<int>(kBoundaries.size()));
  ASSERT_EQ(with_hook->proposals.size(), without->proposals.size());
  for (size_t i = 0; i < without->proposals.size(); ++i) {
    EXPECT_EQ(with_hook->proposals[i].fused, without->proposals[i].fused);
  }
}

// Cancelling at the n-th boundary stops there: the hook is not asked again, and the Status is the
// hook's own (code and message).
TEST_F(DetectCancellationTest, StopsAtTheBoundaryWhereTheHookSaysSo) {
  for (int stop_at = 1; stop_at <= static_cast<int>(kBoundaries.size()); ++stop_at) {
    int asked = 0;
    DetectOptions options;
    options.cancelled = [&asked, stop_at] {
      ++asked;
      return asked >= stop_at ? Status::Cancelled("client went away") : Status::Ok();
    };
    const Result<Detection> detection = detector_->Detect(frame_, options);
    ASSERT_FALSE(detection.ok()) << "boundary " << kBoundaries[stop_at - 1];
    EXPECT_EQ(detection.status().code(), StatusCode::kCancelled);
    EXPECT_EQ(detection.status().message(), "client went away");
    EXPECT_EQ(asked, stop_at) << "work went on past " << kBoundaries[stop_at - 1];
  }
}

TEST_F(DetectCancellationTest, ADeadlineHookReturnsDeadlineExceeded) {
  std::atomic<bool> expired{true};
  DetectOptions options;
  options.cancelled = [&expired] {
    return expired ? Status::DeadlineExceeded("deadline passed") : Status::Ok();
  };
  const Result<Detection> detection = detector_->Detect(frame_, options);
  ASSERT_FALSE(detection.ok());
  EXPECT_EQ(detection.status().code(), StatusCode::kDeadlineExceeded);
}

TEST(StageTimerTest, KeepsTheFirstStopAndStopsAsking) {
  int asked = 0;
  StageTimer timer([&asked] {
    ++asked;
    return asked == 2 ? Status::Cancelled("stop") : Status::Ok();
  });
  timer.Mark("a");
  EXPECT_TRUE(timer.stopped().ok());
  timer.Mark("b");
  EXPECT_EQ(timer.stopped().code(), StatusCode::kCancelled);
  timer.Mark("c");
  EXPECT_EQ(asked, 2);
  EXPECT_EQ(timer.stopped().code(), StatusCode::kCancelled);
  EXPECT_EQ(timer.times().size(), 3u);
}

}  // namespace
}  // namespace tod
