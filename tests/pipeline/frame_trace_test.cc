// The detector composes the stages once and hands them back in a FrameTrace: asking for the trace
// changes nothing in the detection, and what the trace holds is what the detection was made of.
#include "core/pipeline/frame_trace.h"

#include <gtest/gtest.h>

#include <limits>

#include "core/pipeline/obstacle_detector.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

using FrameTraceTest = TinyDetectorTest;

DetectOptions EveryProposal() {
  DetectOptions options;
  options.max_proposals = std::numeric_limits<int>::max();
  return options;
}

TEST_F(FrameTraceTest, AskingForTheTraceChangesNothingInTheDetection) {
  const cv::Mat3b frame = RoadFrame(512, 256);
  const Result<Detection> plain = detector_->Detect(frame, EveryProposal());
  FrameTrace trace;
  const Result<Detection> traced = detector_->Detect(frame, EveryProposal(), &trace);
  ASSERT_TRUE(plain.ok()) << plain.status().ToString();
  ASSERT_TRUE(traced.ok()) << traced.status().ToString();
  EXPECT_EQ(cv::norm(plain->probability, traced->probability, cv::NORM_INF), 0.0);
  ASSERT_EQ(plain->proposals.size(), traced->proposals.size());
  for (std::size_t i = 0; i < plain->proposals.size(); ++i) {
    EXPECT_EQ(plain->proposals[i].box, traced->proposals[i].box);
    EXPECT_EQ(plain->proposals[i].fused, traced->proposals[i].fused);
  }
  ASSERT_EQ(plain->obstacles.size(), traced->obstacles.size());
  std::vector<std::string> stages;
  for (const auto& [stage, ms] : traced->timings) stages.push_back(stage);
  EXPECT_EQ(stages, (std::vector<std::string>{"calibration", "edges", "superpixels", "occlusion", "proposals",
                                              "features", "regression", "probability_map"}));
}

TEST_F(FrameTraceTest, TheTraceHoldsWhatTheDetectionWasMadeOf) {
  const cv::Mat3b frame = RoadFrame(512, 256);
  FrameTrace trace;
  const Result<Detection> detection = detector_->Detect(frame, EveryProposal(), &trace);
  ASSERT_TRUE(detection.ok()) << detection.status().ToString();
  const int layers = trace.geometry.regions.num_layers();
  ASSERT_GT(layers, 1);
  EXPECT_EQ(trace.oaocc.occlusion.size(), trace.oaocc.r1.rect().size());
  ASSERT_EQ(trace.regions.per_region.size(), static_cast<std::size_t>(layers));
  ASSERT_EQ(trace.regions.stats.size(), static_cast<std::size_t>(layers));
  // The merge keeps at most every region's boxes, and each region reports the boxes it kept.
  std::size_t region_boxes = 0;
  for (const RegionProposals& r : trace.regions.per_region) region_boxes += r.boxes.size();
  const std::size_t merged = trace.regressed.proposals.boxes.size();
  EXPECT_GT(merged, 0u);
  EXPECT_LE(merged, region_boxes);
  EXPECT_GT(trace.regions.stats.front().windows_visited, 0);
  // Every regressed proposal is listed, best fused first; the served map is the detection's.
  ASSERT_EQ(trace.fused.size(), merged);
  ASSERT_EQ(detection->proposals.size(), merged);
  float best = 0.f;
  for (const ScoredBox& b : trace.fused) best = std::max(best, b.score);
  EXPECT_EQ(detection->proposals.front().fused, best);
  EXPECT_EQ(cv::norm(trace.served, detection->probability, cv::NORM_INF), 0.0);
  EXPECT_FALSE(trace.components.empty());
  EXPECT_EQ(trace.map_superpixels().crop, trace.oaocc.r1);
}

TEST_F(FrameTraceTest, ARefusedFrameLeavesAnEmptyTrace) {
  FrameTrace trace;
  trace.fused.push_back({Box{1, 2, 3, 4}, 0.5f});  // left over from an earlier frame
  const Result<Detection> detection =
      detector_->Detect(cv::Mat3b(8, 8, cv::Vec3b(0, 0, 0)), DetectOptions{}, &trace);
  ASSERT_FALSE(detection.ok());
  EXPECT_TRUE(trace.fused.empty());
  EXPECT_TRUE(trace.regions.per_region.empty());
}

}  // namespace
}  // namespace tod
