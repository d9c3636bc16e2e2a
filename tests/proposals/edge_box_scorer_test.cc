#include "core/proposals/edge_box_scorer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/proposals/edge_groups.h"
#include "tests/proposals/test_maps.h"

namespace tod {
namespace {

using testing::DrawRectangleContour;

TEST(ScoreSingleBoxTest, EnclosedContourScoresItsMagnitudeOverTheNormaliser) {
  // Square outline x, y in [10, 19]: 36 pixels of value 1, plus one isolated pixel at the centre.
  // Box [8, 21]^2 (inclusive): no group crosses its sides, so nothing is removed by the walk;
  // v = 36 + 1 (all group magnitude, whatever the grouping) - 1 (edges of the centre box
  // [8 + 3, 8 + 3 + 6]^2 = [11, 17]^2, which holds only the centre pixel) = 36;
  // normaliser (floor(13 / 2) + floor(13 / 2))^-1.5 = 12^-1.5.
  cv::Mat1f map(40, 40, 0.f);
  DrawRectangleContour(map, 10, 10, 19, 19);
  map(15, 15) = 1.f;
  const EdgeBoxParams params;
  EXPECT_NEAR(ScoreSingleBox(map, Box{8, 8, 14, 14}, params), 36.f / std::pow(12.f, 1.5f), 1e-4f);
}

TEST(ScoreSingleBoxTest, BoxCrossingALongEdgeScoresLowerThanEnclosingBox) {
  cv::Mat1f map(80, 120, 0.f);
  DrawRectangleContour(map, 20, 20, 39, 39);
  for (int x = 1; x < 119; ++x) map(60, x) = 1.f;  // long horizontal edge
  const EdgeBoxParams params;
  const float enclosing = ScoreSingleBox(map, Box{18, 18, 24, 24}, params);
  const float crossing = ScoreSingleBox(map, Box{60, 50, 24, 24}, params);
  EXPECT_GT(enclosing, params.min_score);
  EXPECT_LT(crossing, enclosing);
  // A box cutting through the contour: its groups touch the sides and are removed.
  EXPECT_LT(ScoreSingleBox(map, Box{18, 18, 12, 24}, params), enclosing);
}

TEST(ScoreSingleBoxTest, DegenerateInputsScoreZero) {
  cv::Mat1f map(40, 40, 0.f);
  DrawRectangleContour(map, 10, 10, 19, 19);
  const EdgeBoxParams params;
  EXPECT_EQ(ScoreSingleBox(map, Box{}, params), 0.f);
  EXPECT_EQ(ScoreSingleBox(map, Box{100, 100, 5, 5}, params), 0.f);  // off the map
  EXPECT_EQ(ScoreSingleBox(cv::Mat1f(), Box{0, 0, 5, 5}, params), 0.f);
  EdgeBoxParams bad = params;
  bad.alpha = 2.f;
  EXPECT_EQ(ScoreSingleBox(map, Box{8, 8, 14, 14}, bad), 0.f);
  // Partly off the map: clipped, same as the clipped box.
  EXPECT_EQ(ScoreSingleBox(map, Box{-5, -5, 27, 27}, params),
            ScoreSingleBox(map, Box{0, 0, 22, 22}, params));
}

TEST(ScoreEdgeBoxesTest, IsolatedRectangleIsFoundInTheTopFive) {
  cv::Mat1f map(80, 100, 0.f);
  DrawRectangleContour(map, 30, 20, 59, 49);
  const Box truth{30, 20, 30, 30};
  const auto boxes = ScoreEdgeBoxes(map, EdgeBoxParams{});
  ASSERT_FALSE(boxes.empty());
  bool found = false;
  for (size_t i = 0; i < std::min<size_t>(5, boxes.size()); ++i) {
    found = found || BoxIoU(boxes[i].box, truth) > 0.7;
  }
  EXPECT_TRUE(found) << "best box " << boxes[0].box.x << "," << boxes[0].box.y << " "
                     << boxes[0].box.w << "x" << boxes[0].box.h;
}

TEST(ScoreEdgeBoxesTest, OutputIsSortedInsideTheMapAndReproducible) {
  cv::Mat1f map(90, 120, 0.f);
  DrawRectangleContour(map, 10, 10, 39, 29);
  DrawRectangleContour(map, 60, 40, 99, 79, 0.6f);
  cv::circle(map, {45, 60}, 12, cv::Scalar(0.8f));
  EdgeBoxParams params;
  params.max_boxes = 50;
  EdgeBoxStats stats;
  const auto boxes = ScoreEdgeBoxes(map, params, &stats);
  ASSERT_FALSE(boxes.empty());
  EXPECT_LE(boxes.size(), 50u);
  EXPECT_EQ(stats.boxes_out, static_cast<long long>(boxes.size()));
  EXPECT_GE(stats.windows_visited, stats.windows_past_early_exit);
  EXPECT_GE(stats.windows_past_early_exit, stats.windows_nonzero);
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i].box;
    EXPECT_GE(b.x, 0);
    EXPECT_GE(b.y, 0);
    EXPECT_LE(b.right(), map.cols);
    EXPECT_LE(b.bottom(), map.rows);
    EXPECT_GE(boxes[i].score, params.min_score);
    if (i > 0) {
      EXPECT_GE(boxes[i - 1].score, boxes[i].score);
    }
    // The returned box is exactly the pixel set that was scored.
    EXPECT_NEAR(ScoreSingleBox(map, b, params), boxes[i].score, 1e-5f);
    for (size_t j = 0; j < i; ++j) EXPECT_LE(BoxIoU(boxes[j].box, b), params.beta);
  }
  const auto again = ScoreEdgeBoxes(map, params);
  ASSERT_EQ(again.size(), boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) EXPECT_EQ(again[i].box, boxes[i].box);
}

TEST(ScoreEdgeBoxesTest, StatsCountTheEdgePixelsAndGroupsOfTheMap) {
  // Two square outlines of 36 pixels each, plus faint pixels at edge_min_mag that are no edge.
  cv::Mat1f map(60, 80, 0.f);
  DrawRectangleContour(map, 10, 10, 19, 19);
  DrawRectangleContour(map, 40, 30, 49, 39);
  const EdgeBoxParams params;
  for (int x = 55; x < 75; ++x) map(50, x) = params.edge_min_mag;
  EdgeBoxStats stats;
  ScoreEdgeBoxes(map, params, &stats);
  EXPECT_EQ(stats.edge_pixels, 72);
  const EdgeGroups groups = BuildEdgeGroups(
      map, {params.edge_min_mag, params.edge_merge_thr, params.cluster_min_mag, params.gamma});
  EXPECT_GE(groups.count(), 2);
  EXPECT_EQ(stats.edge_groups, groups.count());
}

TEST(ScoreEdgeBoxesTest, RefinementNeverLowersAScore) {
  cv::Mat1f map(80, 100, 0.f);
  DrawRectangleContour(map, 30, 20, 59, 49);
  EdgeBoxParams params;
  params.refine = false;
  const auto plain = ScoreEdgeBoxes(map, params);
  params.refine = true;
  const auto refined = ScoreEdgeBoxes(map, params);
  ASSERT_FALSE(plain.empty());
  ASSERT_FALSE(refined.empty());
  EXPECT_GE(refined[0].score, plain[0].score);
}

TEST(ScoreEdgeBoxesTest, MultistrideVisitsMoreWindows) {
  cv::Mat1f map(80, 100, 0.f);
  DrawRectangleContour(map, 30, 20, 59, 49);
  EdgeBoxParams params;
  EdgeBoxStats plain, ms;
  ScoreEdgeBoxes(map, params, &plain);
  params.stride_factor = 0.25f;
  ScoreEdgeBoxes(map, params, &ms);
  EXPECT_GT(ms.windows_visited, plain.windows_visited);
}

TEST(ScoreEdgeBoxesTest, EmptyAndTinyMapsGiveNoCrash) {
  const EdgeBoxParams params;
  EXPECT_TRUE(ScoreEdgeBoxes(cv::Mat1f(), params).empty());
  EXPECT_TRUE(ScoreEdgeBoxes(cv::Mat1f(50, 60, 0.f), params).empty());
  EXPECT_TRUE(ScoreEdgeBoxes(cv::Mat1f(1, 1, 1.f), params).empty());
  for (const ScoredBox& b : ScoreEdgeBoxes(cv::Mat1f(3, 200, 1.f), params)) {
    EXPECT_LE(b.box.right(), 200);
    EXPECT_LE(b.box.bottom(), 3);
  }
  cv::Mat1f tall(200, 3, 0.f);
  tall.col(1).setTo(1.f);
  for (const ScoredBox& b : ScoreEdgeBoxes(tall, params)) EXPECT_LE(b.box.right(), 3);
}

TEST(ScoreEdgeBoxesTest, NonFiniteEdgeValuesCountAsNoEdge) {
  cv::Mat1f map(80, 100, 0.f);
  DrawRectangleContour(map, 30, 20, 59, 49);
  const auto clean = ScoreEdgeBoxes(map, EdgeBoxParams{});
  map(5, 5) = std::nanf("");
  map(70, 90) = std::numeric_limits<float>::infinity();
  const auto dirty = ScoreEdgeBoxes(map, EdgeBoxParams{});
  ASSERT_EQ(dirty.size(), clean.size());
  for (size_t i = 0; i < clean.size(); ++i) {
    EXPECT_EQ(dirty[i].box, clean[i].box);
    EXPECT_EQ(dirty[i].score, clean[i].score);
  }
}

TEST(ScoreEdgeBoxesTest, InvalidParametersAreReportedAndYieldNothing) {
  cv::Mat1f map(80, 100, 0.f);
  DrawRectangleContour(map, 30, 20, 59, 49);
  EdgeBoxParams params;
  EXPECT_TRUE(ValidateEdgeBoxParams(params).ok());
  params.stride_factor = 0.f;
  const Status s = ValidateEdgeBoxParams(params);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("stride_factor"), std::string::npos);
  EXPECT_TRUE(ScoreEdgeBoxes(map, params).empty());
  params = EdgeBoxParams{};
  params.alpha = std::nanf("");
  EXPECT_NE(ValidateEdgeBoxParams(params).message().find("alpha"), std::string::npos);
  params = EdgeBoxParams{};
  params.min_stride = 0;
  EXPECT_FALSE(ValidateEdgeBoxParams(params).ok());
  // The wide bound: 0 (tau_a, the paper's grid) or a ratio of at least 1.
  params = EdgeBoxParams{};
  params.max_wide_aspect_ratio = 10.f;
  EXPECT_TRUE(ValidateEdgeBoxParams(params).ok());
  params.max_wide_aspect_ratio = 0.5f;
  EXPECT_NE(ValidateEdgeBoxParams(params).message().find("max_wide_aspect_ratio"),
            std::string::npos);
}

TEST(NormaliseToMaxTest, DividesByMaxAndKeepsAllZeroMaps) {
  cv::Mat1f m = (cv::Mat1f(1, 3) << 0.f, 2.f, 4.f);
  const cv::Mat1f n = NormaliseToMax(m);
  EXPECT_FLOAT_EQ(n(0, 1), 0.5f);
  EXPECT_FLOAT_EQ(n(0, 2), 1.f);
  const cv::Mat1f z = NormaliseToMax(cv::Mat1f(2, 2, 0.f));
  EXPECT_EQ(cv::countNonZero(z), 0);
  EXPECT_TRUE(NormaliseToMax(cv::Mat1f()).empty());
}

}  // namespace
}  // namespace tod
