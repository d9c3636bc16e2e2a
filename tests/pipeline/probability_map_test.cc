#include "core/pipeline/probability_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

TEST(FuseScores, TopHalfByOrdrGetsOrdrPlusWeightedObdr) {
  const std::vector<float> ordr = {0.9f, 0.1f, 0.5f, 0.3f};
  const std::vector<float> obdr = {1.0f, 1.0f, 0.5f, 1.0f};
  const std::vector<float> fused = FuseScores(ordr, obdr);
  EXPECT_FLOAT_EQ(fused[0], 0.9f + 0.3f * 1.0f);
  EXPECT_FLOAT_EQ(fused[2], 0.5f + 0.3f * 0.5f);
  EXPECT_FLOAT_EQ(fused[1], 0.f);  // bottom half gated out even with a high OBDR
  EXPECT_FLOAT_EQ(fused[3], 0.f);
}

TEST(FuseScores, OddCountKeepsFloorOfHalfAndTiesAreStable) {
  const std::vector<float> ordr = {0.5f, 0.5f, 0.5f};
  const std::vector<float> fused = FuseScores(ordr, {0.f, 0.f, 0.f});
  EXPECT_FLOAT_EQ(fused[0], 0.5f);  // floor(1.5) = 1 box kept: the first of the tie
  EXPECT_FLOAT_EQ(fused[1], 0.f);
  EXPECT_FLOAT_EQ(fused[2], 0.f);
}

// Brute force of §7 for comparison: accumulate each kept box pixel by pixel.
cv::Mat1f BruteForceMap(const std::vector<ScoredBox>& kept_top, cv::Size size) {
  cv::Mat1f m(size, 0.f);
  for (const auto& b : kept_top) m(ClipToImage(b.box, size.width, size.height).rect()) += b.score;
  double peak;
  cv::minMaxLoc(m, nullptr, &peak);
  if (peak > 0) m /= peak;
  return m;
}

TEST(ProbabilityMap, MatchesBruteForceAccumulationAndPeaksOnTheObstacle) {
  // Four disjoint boxes above 0.25 (two of them overlapping heavily -> one removed by NMS 0.7).
  std::vector<ScoredBox> boxes = {
      {{10, 10, 10, 10}, 0.9f}, {{11, 10, 10, 10}, 0.8f},  // IoU 0.82 with the first: removed
      {{40, 5, 8, 8}, 0.7f},    {{5, 30, 12, 6}, 0.6f},
      {{30, 30, 5, 5}, 0.5f},   {{0, 0, 64, 48}, 0.2f}};  // below 0.25: dropped
  const cv::Mat1f map = AccumulateProbabilityMap(boxes, {64, 48}).value();
  // Kept after NMS: 0.9, 0.7, 0.6, 0.5 -> top half = the 0.9 and 0.7 boxes.
  const cv::Mat1f expected = BruteForceMap({boxes[0], boxes[2]}, {64, 48});
  EXPECT_LT(cv::norm(map, expected, cv::NORM_INF), 1e-5);
  EXPECT_FLOAT_EQ(map(15, 15), 1.f);
  EXPECT_NEAR(map(8, 44), 0.7f / 0.9f, 1e-5);
  EXPECT_FLOAT_EQ(map(33, 10), 0.f);
}

// With superpixel shares, a box adds its score to a pixel times the share of the pixel's
// superpixel it holds: an obstacle's superpixel inside the box keeps the box's score, the road's
// superpixel running on past it gets its share, and pixels off the crop the whole score.
TEST(ProbabilityMap, SuperpixelSharesWeighEachBoxsPixels) {
  const cv::Size size(40, 30);
  MapSuperpixels superpixels;
  superpixels.crop = {0, 10, 40, 20};  // rows 10..29 have superpixels, rows 0..9 none
  superpixels.superpixels.count = 2;
  superpixels.superpixels.labels = cv::Mat1i(20, 40, 1);           // road: label 1
  superpixels.superpixels.labels(cv::Rect(10, 5, 5, 5)).setTo(2);  // an obstacle: label 2
  // One box around the obstacle (frame rows 14..20), one in the rows without superpixels.
  const std::vector<ScoredBox> boxes = {{{8, 14, 9, 7}, 0.9f}, {{30, 2, 5, 5}, 0.8f}};
  ProbabilityMapParams params;
  params.top_fraction = 1.f;
  params.superpixel_shares = true;
  const Result<cv::Mat1f> map = AccumulateProbabilityMap(boxes, size, params, &superpixels);
  ASSERT_TRUE(map.ok()) << map.status().message();
  // Road pixels in the box: the box holds 63 - 25 = 38 of the road's 800 - 25 pixels.
  const float road = 0.9f * 38.f / 775.f;
  EXPECT_FLOAT_EQ((*map)(17, 12), 1.f);  // the obstacle: the frame's peak
  EXPECT_NEAR((*map)(14, 8), road / 0.9f, 1e-6);
  EXPECT_NEAR((*map)(3, 31), 0.8f / 0.9f, 1e-6);  // off the crop: the whole score
  EXPECT_EQ((*map)(25, 25), 0.f);
  // Without shares, the same boxes are painted whole.
  params.superpixel_shares = false;
  const cv::Mat1f whole = AccumulateProbabilityMap(boxes, size, params).value();
  EXPECT_FLOAT_EQ(whole(14, 8), 1.f);
  // Shares without the frame's superpixels are the caller's error, not whole boxes.
  params.superpixel_shares = true;
  const Result<cv::Mat1f> refused = AccumulateProbabilityMap(boxes, size, params);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
}

// A frame's accumulated boxes are found once and serve every map painted from them: the map's
// boxes keep their fused scores (the obstacles' evidence), the weighted copy adds score times
// isolation weight, and painting them gives the one-call map, whole or with shares.
TEST(ProbabilityMap, AccumulatedBoxesServeEveryMapOfTheFrame) {
  const auto same = [](const std::vector<ScoredBox>& a, const std::vector<ScoredBox>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
      return x.box == y.box && x.score == y.score;
    });
  };
  std::vector<ScoredBox> boxes;
  for (int i = 0; i < 12; ++i)  // a stripe of similar boxes and a lone one
    boxes.push_back({{4 + 5 * i, 20, 6, 6}, 0.6f + 0.01f * i});
  boxes.push_back({{40, 2, 6, 6}, 0.65f});
  ProbabilityMapParams params;
  params.isolation.exponent = 2.f;
  const MapAccumulation accumulated = AccumulatedBoxes(boxes, params);
  EXPECT_TRUE(same(accumulated.boxes, MapBoxes(boxes, params)));
  const std::vector<float> weights = IsolationWeights(accumulated.boxes, boxes, params.isolation);
  ASSERT_EQ(accumulated.weighted.size(), accumulated.boxes.size());
  for (std::size_t i = 0; i < weights.size(); ++i) {
    EXPECT_EQ(accumulated.weighted[i].box, accumulated.boxes[i].box);
    EXPECT_FLOAT_EQ(accumulated.weighted[i].score, accumulated.boxes[i].score * weights[i]);
  }
  EXPECT_LT(*std::min_element(weights.begin(), weights.end()), 1.f);  // the weights do weigh
  const cv::Size size(70, 40);
  const cv::Mat1f painted = PaintProbabilityMap(accumulated, size, false).value();
  EXPECT_EQ(cv::norm(painted, AccumulateProbabilityMap(boxes, size, params).value(), cv::NORM_INF),
            0.0);
  // Exponent 0: the weighted copy is the map's boxes.
  const MapAccumulation plain = WeighMapBoxes(accumulated.boxes, boxes, BoxIsolationParams{});
  EXPECT_TRUE(same(plain.weighted, plain.boxes));
  // Shares still need the superpixels.
  EXPECT_FALSE(PaintProbabilityMap(accumulated, size, true).ok());
}

TEST(ProbabilityMap, NoBoxesGiveAnAllZeroMap) {
  const cv::Mat1f map = AccumulateProbabilityMap({}, {16, 8}).value();
  EXPECT_EQ(cv::countNonZero(map), 0);
}

TEST(ProbabilityMap, ThresholdedComponentsCarryBoxAreaPeakAndMean) {
  cv::Mat1f p(20, 30, 0.f);
  p(cv::Rect(2, 3, 4, 5)) = 0.8f;
  p(4, 3) = 1.0f;
  p(cv::Rect(20, 10, 3, 3)) = 0.6f;
  const auto comps = ThresholdObstacles(p, 0.5f);
  ASSERT_EQ(comps.size(), 2u);
  EXPECT_EQ(comps[0].box, (Box{2, 3, 4, 5}));
  EXPECT_EQ(comps[0].area, 20);
  EXPECT_FLOAT_EQ(comps[0].peak, 1.0f);
  EXPECT_NEAR(comps[0].mean, (19 * 0.8 + 1.0) / 20, 1e-6);
  EXPECT_EQ(comps[1].box, (Box{20, 10, 3, 3}));
  EXPECT_TRUE(ThresholdObstacles(p, 1.0f).empty());
}

// The reference: the components labelled on the whole map (what ThresholdObstacles did before
// it labelled only the mask's bounding box).
std::vector<ObstacleComponent> WholeMapComponents(const cv::Mat1f& probability, float threshold) {
  const cv::Mat1b mask = probability > threshold;
  cv::Mat1i labels;
  cv::Mat stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<ObstacleComponent> out(std::max(0, n - 1));
  std::vector<double> sums(out.size(), 0.0);
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const int l = labels(y, x);
      if (l == 0) continue;
      out[l - 1].peak = std::max(out[l - 1].peak, probability(y, x));
      sums[l - 1] += probability(y, x);
    }
  for (int l = 1; l < n; ++l) {
    ObstacleComponent& c = out[l - 1];
    c.box = {stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
             stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT)};
    c.area = stats.at<int>(l, cv::CC_STAT_AREA);
    c.mean = static_cast<float>(sums[l - 1] / c.area);
  }
  std::stable_sort(
      out.begin(), out.end(),
      [](const ObstacleComponent& a, const ObstacleComponent& b) { return a.peak > b.peak; });
  return out;
}

// Labelled on the mask's bounding box (grown to even coordinates) or on the whole map, the
// components are the same, in the same order, also where many share one peak value and the box
// starts at odd coordinates.
TEST(ProbabilityMap, ComponentsOfTheMasksBoundingBoxAreThoseOfTheWholeMap) {
  cv::RNG rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    cv::Mat1f p(97, 131, 0.f);
    const int boxes = rng.uniform(1, 60);
    for (int i = 0; i < boxes; ++i) {
      const int x = rng.uniform(3, 120), y = rng.uniform(5, 90);
      const cv::Rect r(x, y, std::min(rng.uniform(1, 9), 131 - x),
                       std::min(rng.uniform(1, 7), 97 - y));
      p(r) += 0.25f * static_cast<float>(rng.uniform(1, 4));  // few distinct values: equal peaks
    }
    for (const float threshold : {0.f, 0.3f, 0.6f}) {
      const std::vector<ObstacleComponent> got = ThresholdObstacles(p, threshold);
      const std::vector<ObstacleComponent> want = WholeMapComponents(p, threshold);
      ASSERT_EQ(got.size(), want.size()) << trial << " " << threshold;
      for (std::size_t k = 0; k < got.size(); ++k) {
        EXPECT_EQ(got[k].box, want[k].box) << trial << " " << threshold << " " << k;
        EXPECT_EQ(got[k].area, want[k].area);
        EXPECT_EQ(got[k].peak, want[k].peak);
        EXPECT_EQ(got[k].mean, want[k].mean);
      }
    }
  }
  EXPECT_TRUE(ThresholdObstacles(cv::Mat1f(8, 8, 0.f), 0.f).empty());
}

TEST(RankedAboveThreshold, StrictAndSorted) {
  const auto r = RankedAboveThreshold(
      {{{0, 0, 1, 1}, 0.25f}, {{1, 1, 1, 1}, 0.3f}, {{2, 2, 1, 1}, 0.9f}}, 0.25f);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_FLOAT_EQ(r[0].score, 0.9f);
  EXPECT_FLOAT_EQ(r[1].score, 0.3f);
}

TEST(CalibratedProbabilityMap, EachPixelHoldsTheCalibratedScoreOfItsStrongestGatedBox) {
  ObstacleCalibration calibration;
  calibration.fitted = true;
  calibration.slope = 6.0;
  calibration.intercept = -3.0;
  const std::vector<ScoredBox> boxes = {
      {{10, 10, 20, 20}, 0.4f}, {{15, 15, 10, 10}, 0.9f},  // nested: the stronger one wins
      {{18, 12, 20, 5}, 0.6f},                             // overlaps both
      {{50, 40, 30, 30}, 0.f},                             // gated out (F = 0): not painted
      {{70, 0, 40, 10}, 0.3f},                             // runs past the right border
  };
  const cv::Size size(100, 60);
  // No superpixels (a crop of size 0): every pixel lies outside them, so a box holds all of its
  // segment and paints its whole area.
  auto map = CalibratedProbabilityMap(boxes, size, calibration, Superpixels{}, Box{});
  ASSERT_TRUE(map.ok()) << map.status().message();
  // Reference: for every pixel, the box with the largest F over it.
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      float best = 0.f;
      for (const ScoredBox& b : boxes)
        if (b.score > 0.f && b.box.rect().contains({x, y})) best = std::max(best, b.score);
      const float expected =
          best > 0.f ? static_cast<float>(CalibratedScore(calibration, best)) : 0.f;
      ASSERT_FLOAT_EQ((*map)(y, x), expected) << x << "," << y;
    }
  // Not divided by a per-frame maximum: a frame of weak boxes stays low.
  double peak = 0;
  cv::minMaxLoc(*map, nullptr, &peak);
  EXPECT_NEAR(peak, CalibratedScore(calibration, 0.9), 1e-6);
  EXPECT_LT(peak, 1.0);
}

TEST(CalibratedProbabilityMap, RefusesAnUnfittedCalibration) {
  const auto map = CalibratedProbabilityMap({{{0, 0, 4, 4}, 0.5f}}, {8, 8}, ObstacleCalibration{},
                                            Superpixels{}, Box{});
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.status().code(), StatusCode::kFailedPrecondition);
}

// A 40 x 20 crop at (10, 5) of a 60 x 40 frame: superpixel 1 (the "road") is everything but a
// 6 x 4 block, superpixel 2 (the "obstacle", frame 30..35 x 13..16), framed by a 1-pixel
// boundary (label 0).
class SuperpixelShareMapTest : public ::testing::Test {
 protected:
  SuperpixelShareMapTest() {
    calibration_.fitted = true;
    calibration_.slope = 4.0;
    calibration_.intercept = -2.0;
    superpixels_.count = 2;
    superpixels_.labels = cv::Mat1i(20, 40, 1);
    superpixels_.labels(cv::Rect(19, 7, 8, 6)).setTo(0);
    superpixels_.labels(cv::Rect(20, 8, 6, 4)).setTo(2);
  }
  cv::Mat1f Map(const std::vector<ScoredBox>& boxes) const {
    auto map = CalibratedProbabilityMap(boxes, {60, 40}, calibration_, superpixels_, crop_);
    EXPECT_TRUE(map.ok()) << map.status().message();
    return map.ok() ? *map : cv::Mat1f();
  }
  float Calibrated(float fused) const {
    return static_cast<float>(CalibratedScore(calibration_, fused));
  }

  ObstacleCalibration calibration_;
  Superpixels superpixels_;
  const Box crop_{10, 5, 40, 20};
};

TEST_F(SuperpixelShareMapTest, WeightsEachPixelByTheShareOfItsSuperpixelInTheBox) {
  const Box box{27, 10, 12, 10};  // frames the obstacle with a margin of road around it
  const cv::Mat1f map = Map({{box, 0.8f}});
  ASSERT_FALSE(map.empty());
  int road_in_box = 0;
  for (int y = box.y; y < box.bottom(); ++y)
    for (int x = box.x; x < box.right(); ++x)
      road_in_box += superpixels_.labels(y - crop_.y, x - crop_.x) == 1;
  const float road_share = static_cast<float>(road_in_box) /
                           static_cast<float>(cv::countNonZero(superpixels_.labels == 1));
  const float p = Calibrated(0.8f);
  EXPECT_FLOAT_EQ(map(14, 32), p);               // obstacle: its superpixel is all inside
  EXPECT_FLOAT_EQ(map(13, 29), p);               // its contour (label 0) takes its share
  EXPECT_FLOAT_EQ(map(10, 27), p * road_share);  // the road in the corner: a small share
  EXPECT_LT(road_share, 0.2f);
  EXPECT_FLOAT_EQ(map(9, 27), 0.f);  // outside the box
}

TEST_F(SuperpixelShareMapTest, TakesTheLargestWeightedScoreOverThePixel) {
  // A weak box framing the obstacle, and a strong wide one over the top rows of the crop that
  // holds most of the road but only the obstacle's first row (a quarter of it).
  const Box obstacle_box{29, 12, 8, 6}, wide_box{10, 5, 40, 9};
  const cv::Mat1f map = Map({{obstacle_box, 0.5f}, {wide_box, 0.9f}});
  ASSERT_FALSE(map.empty());
  const float road_area = static_cast<float>(cv::countNonZero(superpixels_.labels == 1));
  auto road_share = [&](const Box& b) {
    const Box on_crop = Intersect(b, crop_);
    const cv::Rect local(on_crop.x - crop_.x, on_crop.y - crop_.y, on_crop.w, on_crop.h);
    return static_cast<float>(cv::countNonZero(superpixels_.labels(local) == 1)) / road_area;
  };
  // The obstacle's first row, in both boxes: the weak box holds all of it and wins.
  ASSERT_GT(Calibrated(0.5f), 0.25f * Calibrated(0.9f));
  EXPECT_FLOAT_EQ(map(13, 32), Calibrated(0.5f));
  EXPECT_FLOAT_EQ(map(14, 32), Calibrated(0.5f));  // only in the weak box
  // Road in both boxes: the larger weighted score, which is the wide box's larger share.
  ASSERT_GT(Calibrated(0.9f) * road_share(wide_box), Calibrated(0.5f) * road_share(obstacle_box));
  EXPECT_FLOAT_EQ(map(12, 29), Calibrated(0.9f) * road_share(wide_box));
  EXPECT_FLOAT_EQ(map(17, 29), Calibrated(0.5f) * road_share(obstacle_box));  // weak box only
}

TEST_F(SuperpixelShareMapTest, PixelsOutsideTheCropTakeTheBoxScore) {
  const cv::Mat1f map = Map({{{0, 30, 5, 5}, 0.5f}});
  ASSERT_FALSE(map.empty());
  EXPECT_FLOAT_EQ(map(32, 2), Calibrated(0.5f));
}

}  // namespace
}  // namespace tod
