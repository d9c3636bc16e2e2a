#include "core/pipeline/box_isolation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/pipeline/probability_map.h"

namespace tod {
namespace {

// A frame's boxes: one small box alone, and a stripe covered by a row of boxes of the same size
// side by side (what a lane marking gives the proposal stage).
std::vector<ScoredBox> AloneAndStripe() {
  std::vector<ScoredBox> boxes = {{Box{100, 100, 20, 20}, 0.9f}};
  for (int i = 0; i < 10; ++i) boxes.push_back({Box{300 + 20 * i, 300, 20, 20}, 0.9f});
  return boxes;
}

TEST(IsolationWeights, ExponentZeroWeighsEveryBoxOne) {
  const std::vector<ScoredBox> boxes = AloneAndStripe();
  for (const float w : IsolationWeights(boxes, boxes, BoxIsolationParams{})) EXPECT_EQ(w, 1.f);
}

TEST(IsolationWeights, ABoxAloneKeepsItsScoreABoxInAStripeLosesIt) {
  const std::vector<ScoredBox> boxes = AloneAndStripe();
  const std::vector<float> w = IsolationWeights(boxes, boxes, {.exponent = 1.f});
  EXPECT_FLOAT_EQ(w[0], 1.f);  // its own centre, nothing else in its surround
  // A stripe box's surround (3 x 3 boxes) holds its own centre and its two neighbours' in the row.
  EXPECT_FLOAT_EQ(w[5], 1.f / 3.f);
  EXPECT_FLOAT_EQ(w[1], 1.f / 2.f);  // the stripe's end: one neighbour
  const std::vector<float> squared = IsolationWeights(boxes, boxes, {.exponent = 2.f});
  EXPECT_FLOAT_EQ(squared[5], 1.f / 9.f);
}

TEST(IsolationWeights, OnlyTheBestContextBoxesCountAndABoxWithNoneHoldsItsOwn) {
  std::vector<ScoredBox> frame = AloneAndStripe();
  frame[0].score = 0.1f;  // the lone box is now the frame's worst
  const std::vector<ScoredBox> asked = {frame[0], frame[5]};
  const BoxIsolationParams two_best{.exponent = 1.f, .context_boxes = 2};
  const std::vector<float> w = IsolationWeights(asked, frame, two_best);
  // Context: the first two stripe boxes (ties keep their order), far from both asked boxes.
  EXPECT_FLOAT_EQ(w[0], 1.f);
  EXPECT_FLOAT_EQ(w[1], 1.f);
  const std::vector<float> near = IsolationWeights({frame[2]}, frame, two_best);
  EXPECT_FLOAT_EQ(near[0], 1.f / 2.f);  // its own centre and its neighbour's, both in the context
}

TEST(IsolationWeights, TheSurroundScalesWithTheBox) {
  const std::vector<ScoredBox> boxes = AloneAndStripe();
  // A surround of 5 box widths reaches two neighbours on each side.
  const std::vector<float> w = IsolationWeights(boxes, boxes, {.exponent = 1.f, .surround = 5.f});
  EXPECT_FLOAT_EQ(w[5], 1.f / 5.f);
}

// The map with an exponent: the stripe's boxes add less than the lone box, so the map, divided
// by its maximum, now peaks on the lone box; with exponent 0 it is the paper's map.
TEST(IsolationWeights, TheMapPeaksOnTheIsolatedBox) {
  std::vector<ScoredBox> boxes = AloneAndStripe();
  boxes[0].score = 0.5f;  // weaker than each stripe box on its own
  // Overlapping stripe boxes so that the paper's map sums them: shifted copies (IoU 1/3 with
  // their neighbours, so NMS at 0.7 keeps them). Centres at x = 310, 320, ..., 500.
  for (int i = 0; i < 9; ++i) boxes.push_back({Box{310 + 20 * i, 300, 20, 20}, 0.9f});
  ProbabilityMapParams paper;
  paper.top_fraction = 1.f;
  const cv::Mat1f plain = AccumulateProbabilityMap(boxes, {640, 480}, paper).value();
  EXPECT_LT(plain(110, 110), 0.5f);
  EXPECT_FLOAT_EQ(plain(310, 335), 1.f);
  ProbabilityMapParams isolated = paper;
  isolated.isolation.exponent = 4.f;
  const cv::Mat1f weighted = AccumulateProbabilityMap(boxes, {640, 480}, isolated).value();
  EXPECT_FLOAT_EQ(weighted(110, 110), 1.f);
  // Over the pixel: the box at x 320 (3 centres inside, 6 in its surround: the stripe starts at
  // 310) and the one at x 330 (3 of 7), against the lone box's 0.5.
  EXPECT_NEAR(weighted(310, 335), 0.9 * (std::pow(3.0 / 6.0, 4) + std::pow(3.0 / 7.0, 4)) / 0.5,
              1e-4);
}

}  // namespace
}  // namespace tod
