#include <gtest/gtest.h>

#include <random>

#include "core/proposals/edge_box_scorer.h"

namespace tod {
namespace {

TEST(NmsTest, RemovesAboveThresholdKeepsExactlyAtThreshold) {
  // A = 4x4; E = 5x4 containing A: IoU 16 / 20 = 0.8 > 0.75 -> removed.
  // B = 4x3 inside A: IoU 12 / 16 = 0.75 exactly -> kept; B vs E = 12 / 20, irrelevant.
  const ScoredBox a{{0, 0, 4, 4}, 0.9f}, e{{0, 0, 5, 4}, 0.8f}, b{{0, 0, 4, 3}, 0.7f};
  const auto kept = NonMaximumSuppression({b, e, a}, 0.75f, 100);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].box, a.box);
  EXPECT_EQ(kept[1].box, b.box);
}

TEST(NmsTest, MaxBoxesAndDegenerateInputs) {
  std::vector<ScoredBox> boxes;
  for (int i = 0; i < 10; ++i) boxes.push_back({{i * 10, 0, 5, 5}, static_cast<float>(i)});
  const auto kept = NonMaximumSuppression(boxes, 0.75f, 3);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0].score, 9.f);
  EXPECT_EQ(kept[2].score, 7.f);
  EXPECT_TRUE(NonMaximumSuppression({}, 0.75f, 3).empty());
  EXPECT_TRUE(NonMaximumSuppression(boxes, 0.75f, 0).empty());
  // Empty boxes never overlap anything.
  EXPECT_EQ(NonMaximumSuppression({{{0, 0, 0, 0}, 1.f}, {{0, 0, 0, 0}, 0.5f}}, 0.75f, 5).size(),
            2u);
}

// Plain O(n^2) greedy NMS as the reference for the binned version.
std::vector<ScoredBox> Reference(std::vector<ScoredBox> boxes, float thr, int max_boxes) {
  std::stable_sort(boxes.begin(), boxes.end(),
                   [](const ScoredBox& a, const ScoredBox& b) { return a.score > b.score; });
  std::vector<ScoredBox> kept;
  for (const ScoredBox& c : boxes) {
    if (static_cast<int>(kept.size()) >= max_boxes) break;
    bool keep = true;
    for (const ScoredBox& k : kept) keep = keep && BoxIoU(c.box, k.box) <= thr;
    if (keep) kept.push_back(c);
  }
  return kept;
}

// NonMaximumSuppression keeps the boxes plain greedy NMS keeps, in its order, at every threshold.
void ExpectSameAsPlainGreedyNms(const std::vector<ScoredBox>& boxes,
                                std::initializer_list<float> thresholds) {
  for (const float thr : thresholds) {
    const auto expected = Reference(boxes, thr, 100000);
    const auto got = NonMaximumSuppression(boxes, thr, 100000);
    ASSERT_EQ(got.size(), expected.size()) << thr;
    for (size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].box, expected[i].box) << thr << i;
  }
}

TEST(NmsTest, BinnedNmsEqualsPlainGreedyNms) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> pos(0, 40), size(1, 30), score(0, 50);
  for (const float thr : {0.3f, 0.5f, 0.75f, 0.9f}) {
    std::vector<ScoredBox> boxes;
    for (int i = 0; i < 1500; ++i) {
      boxes.push_back({{pos(rng), pos(rng), size(rng), size(rng)},
                       static_cast<float>(score(rng))});  // many ties
    }
    const auto expected = Reference(boxes, thr, 400);
    const auto got = NonMaximumSuppression(boxes, thr, 400);
    ASSERT_EQ(got.size(), expected.size()) << thr;
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].box, expected[i].box) << thr << " " << i;
      EXPECT_EQ(got[i].score, expected[i].score);
    }
  }
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

TEST(NmsTest, NanScoresAreDropped) {
  const auto kept = NonMaximumSuppression(
      {{{0, 0, 4, 4}, std::nanf("")}, {{10, 0, 4, 4}, 0.5f}, {{20, 0, 4, 4}, 0.7f}}, 0.75f, 10);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].score, 0.7f);
  EXPECT_EQ(kept[1].score, 0.5f);
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

// The position grid must not lose suppressions for boxes far apart in size and place, nor for
// negative or huge coordinates (its cells grow to fit).
TEST(NmsTest, GridIndexEqualsPlainGreedyNmsOnWideRanges) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pos(-300, 2000), size(1, 400), jitter(-6, 6), score(0, 200);
  std::vector<ScoredBox> boxes;
  for (int i = 0; i < 600; ++i) {
    const Box base{pos(rng), pos(rng), size(rng), size(rng)};
    for (int k = 0; k < 4; ++k) {  // near-duplicates, the case NMS exists for
      boxes.push_back(
          {{base.x + jitter(rng), base.y + jitter(rng), base.w + jitter(rng), base.h + jitter(rng)},
           static_cast<float>(score(rng))});
    }
  }
  boxes.push_back({{1000000000, -1000000000, 50, 50}, 3.f});
  boxes.push_back({{1000000002, -1000000001, 50, 51}, 2.f});  // IoU 0.92 with the one above
  ExpectSameAsPlainGreedyNms(boxes, {0.5f, 0.75f});
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

// Many small boxes over a tall strip, as a real frame's far layers give: the grids of the small
// bins get columns of hundreds of cells, and a candidate searches cells on every side of its own.
TEST(NmsTest, GridIndexEqualsPlainGreedyNmsOnDenseSmallBoxes) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> x(0, 900), y(0, 700), size(2, 24), jitter(-3, 3);
  std::uniform_real_distribution<float> score(0.f, 1.f);
  std::vector<ScoredBox> boxes;
  for (int i = 0; i < 1500; ++i) {
    const Box base{x(rng), y(rng), size(rng), size(rng)};
    for (int k = 0; k < 3; ++k) {
      boxes.push_back({{base.x + jitter(rng), base.y + jitter(rng),
                        std::max(1, base.w + jitter(rng)), std::max(1, base.h + jitter(rng))},
                       score(rng)});
    }
  }
  ExpectSameAsPlainGreedyNms(boxes, {0.4f, 0.65f, 0.8f});
}

}  // namespace
}  // namespace tod
