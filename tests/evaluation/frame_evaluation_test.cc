#include "core/evaluation/frame_evaluation.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "core/evaluation/evaluator.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {

// RoadFrame with its near block labelled as the one obstacle and the rest below the sky as road.
Sample RoadSample(int width, int height) {
  Sample s;
  s.name = "road";
  s.image = RoadFrame(width, height);
  const Box near{static_cast<int>(0.66 * width), static_cast<int>(0.80 * height),
                 static_cast<int>(0.06 * width), static_cast<int>(0.10 * height)};
  s.obstacle = cv::Mat1b::zeros(height, width);
  s.obstacle(near.rect()).setTo(1);
  s.road = cv::Mat1b::zeros(height, width);
  s.road.rowRange(height * 37 / 100, height).setTo(1);
  s.road.setTo(0, s.obstacle);
  s.ignore = cv::Mat1b::zeros(height, width);
  s.instances.push_back({1, near, cv::Mat1b(near.h, near.w, uchar{1})});
  return s;
}

TEST(FrameEvaluation, GivesEveryVariantAndTimesTheDetectorsPathOnly) {
  const ObstacleDetector detector(TinyBundle(), "tiny");
  const Sample sample = RoadSample(512, 256);
  const Result<FrameEvaluation> frame = EvaluateFrame(detector, sample);
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();

  std::set<std::string> expected(ProposalVariants().begin(), ProposalVariants().end());
  expected.insert(RegressionVariants().begin(), RegressionVariants().end());
  std::set<std::string> ranked;
  for (const auto& [variant, boxes] : frame->ranked) ranked.insert(variant);
  EXPECT_EQ(ranked, expected);
  EXPECT_FALSE(frame->ranked.at("OAOCC+OLP@4+MS").empty());

  // No fitted calibration in the tiny bundle: the paper's three maps, in their table order.
  ASSERT_EQ(frame->maps.size(), RegressionVariants().size());
  for (std::size_t i = 0; i < frame->maps.size(); ++i) {
    EXPECT_EQ(frame->maps[i].first, RegressionVariants()[i]);
    EXPECT_EQ(frame->maps[i].second.size(), sample.image.size());
  }

  // The timed stages are the detector's, once each; the baselines and OP are not among them.
  std::vector<std::string> stages;
  double sum = 0;
  for (const auto& [stage, ms] : frame->stage_times) {
    stages.push_back(stage);
    sum += ms;
  }
  EXPECT_EQ(stages,
            (std::vector<std::string>{"calibration", "edges", "superpixels", "occlusion",
                                      "proposals", "features", "regression", "probability_map"}));
  EXPECT_DOUBLE_EQ(frame->total_ms, sum);
}

TEST(FrameEvaluation, FusionMapIsTheMapDetectServes) {
  const ObstacleDetector detector(TinyBundle(), "tiny");
  const Sample sample = RoadSample(512, 256);
  const Result<FrameEvaluation> frame = EvaluateFrame(detector, sample);
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  const Result<Detection> detected = detector.Detect(sample.image, DetectOptions{});
  ASSERT_TRUE(detected.ok()) << detected.status().ToString();
  const cv::Mat1f* fusion = nullptr;
  for (const auto& [variant, map] : frame->maps)
    if (variant == "BP+Fusion@4") fusion = &map;
  ASSERT_NE(fusion, nullptr);
  EXPECT_EQ(cv::norm(*fusion, detected->probability, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace tod
