#include "core/features/box_features.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace tod {
namespace {

constexpr float kTol = 1e-5f;

// 8x8 map with three boundaries: column 2 at 0.5 (8 px), column 5 rows 0-3 at 0.25 (4 px) and a
// single 0.75 pixel at (row 6, col 6).
cv::Mat1f ThreeBoundaryMap() {
  cv::Mat1f map(8, 8, 0.f);
  for (int y = 0; y < 8; ++y) map(y, 2) = 0.5f;
  for (int y = 0; y < 4; ++y) map(y, 5) = 0.25f;
  map(6, 6) = 0.75f;
  return map;
}

cv::Mat3b Uniform(int rows, int cols, cv::Vec3b bgr) { return cv::Mat3b(rows, cols, bgr); }

TEST(HsvTest, MatchesMatlabRgb2Hsv) {
  const cv::Vec3f red = BgrToHsv({0, 0, 255});
  EXPECT_FLOAT_EQ(red[0], 0.f);
  EXPECT_FLOAT_EQ(red[1], 1.f);
  EXPECT_FLOAT_EQ(red[2], 1.f);
  EXPECT_NEAR(BgrToHsv({0, 255, 0})[0], 1.f / 3.f, kTol);
  EXPECT_NEAR(BgrToHsv({255, 0, 0})[0], 2.f / 3.f, kTol);
  // Orange r=255, g=128, b=0: H = (128/255) / 6.
  EXPECT_NEAR(BgrToHsv({0, 128, 255})[0], (128.0 / 255.0) / 6.0, kTol);
  // Magenta-red r=255, b=43: H = 1 - (43/255)/6 (about 349.9 degrees).
  EXPECT_NEAR(BgrToHsv({43, 0, 255})[0], 1.0 - (43.0 / 255.0) / 6.0, kTol);
  // Grey: H = S = 0, V = level.
  const cv::Vec3f grey = BgrToHsv({64, 64, 64});
  EXPECT_FLOAT_EQ(grey[0], 0.f);
  EXPECT_FLOAT_EQ(grey[1], 0.f);
  EXPECT_NEAR(grey[2], 64.f / 255.f, kTol);
  // Saturation = (max - min) / max.
  EXPECT_NEAR(BgrToHsv({51, 102, 204})[1], (204.0 - 51.0) / 204.0, kTol);
  EXPECT_EQ(BgrToHsv({0, 0, 0}), cv::Vec3f(0.f, 0.f, 0.f));
}

TEST(HsvTest, HueBinEdgesAndRedWrap) {
  EXPECT_EQ(HueBin(0.0), 0);
  EXPECT_EQ(HueBin(14.99), 0);
  EXPECT_EQ(HueBin(15.0), 1);
  EXPECT_EQ(HueBin(30.0), 2);
  EXPECT_EQ(HueBin(107.99), 5);
  EXPECT_EQ(HueBin(108.0), 6);
  EXPECT_EQ(HueBin(240.0), 10);
  EXPECT_EQ(HueBin(344.99), 15);
  EXPECT_EQ(HueBin(345.0), 0);  // the 17th bin [345, 361) is red: merged into bin 0
  EXPECT_EQ(HueBin(350.0), 0);
  EXPECT_EQ(HueBin(359.99), 0);
  // Pure red and a 350-degree pixel both land in bin 0.
  EXPECT_EQ(HueBin(BgrToHsv({0, 0, 255})[0] * 360.0), 0);
  EXPECT_EQ(HueBin(BgrToHsv({43, 0, 255})[0] * 360.0), 0);
  EXPECT_EQ(HueBin(BgrToHsv({64, 0, 255})[0] * 360.0), 15);  // 344.9 degrees
}

TEST(HsvTest, SatValBinsAreUniformWithOneInLastBin) {
  EXPECT_EQ(SatValBin(0.f), 0);
  EXPECT_EQ(SatValBin(0.0624f), 0);
  EXPECT_EQ(SatValBin(0.0625f), 1);
  EXPECT_EQ(SatValBin(0.5f), 8);
  EXPECT_EQ(SatValBin(0.9375f), 15);
  EXPECT_EQ(SatValBin(1.f), 15);
}

TEST(BoxFeaturesTest, EdgeFeaturesOnWholeRegion) {
  const BoxFeatureExtractor extractor(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), {0, 0},
                                      {20, 10});
  ASSERT_TRUE(extractor.status().ok());
  const BoxFeatureVector f = extractor.Compute({0, 0, 8, 8}, 0.42f);
  EXPECT_FLOAT_EQ(f[0], 0.75f);         // max
  EXPECT_FLOAT_EQ(f[1], 0.5f);          // mode: 0.5 occurs 8 times
  EXPECT_NEAR(f[2], 8.0 / 13.0, kTol);  // 8 of 13 edge pixels
  // Centre sub-box [2,6) x [2,6): col 2 rows 2-5 (4 x 0.5) + col 5 rows 2-3 (2 x 0.25).
  EXPECT_NEAR(f[3], 2.5 / 16.0, kTol);
  EXPECT_NEAR(f[4], 6.0 / 16.0, kTol);
  EXPECT_NEAR(f[5], (4.0 + 1.0 + 0.75) / 64.0, kTol);
  EXPECT_NEAR(f[6], 13.0 / 64.0, kTol);
  EXPECT_NEAR(f[7], 64.0 / 200.0, kTol);  // A / (W H)
  EXPECT_FLOAT_EQ(f[8], 1.f);
  EXPECT_FLOAT_EQ(f[9], 0.42f);
  EXPECT_NEAR(f[10], 4.0 / 20.0, kTol);
  EXPECT_NEAR(f[11], 4.0 / 10.0, kTol);
  EXPECT_NEAR(f[12], 8.0 / 20.0, kTol);
  EXPECT_NEAR(f[13], 8.0 / 10.0, kTol);
  // Uniform colour: no spread, and the box is the whole crop so the ring is empty -> 0.
  for (int i = 14; i < 20; ++i) EXPECT_FLOAT_EQ(f[i], 0.f) << "feature " << i;
}

TEST(BoxFeaturesTest, EdgeFeaturesOnSubBoxAndEmptyBox) {
  const BoxFeatureExtractor extractor(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), {0, 0},
                                      {8, 8});
  // Columns 4-7, rows 0-3: only the 0.25 boundary (4 px).
  BoxFeatureVector f = extractor.Compute({4, 0, 4, 4}, 0.f);
  EXPECT_FLOAT_EQ(f[0], 0.25f);
  EXPECT_FLOAT_EQ(f[1], 0.25f);
  EXPECT_FLOAT_EQ(f[2], 1.f);
  EXPECT_NEAR(f[5], 1.0 / 16.0, kTol);
  EXPECT_NEAR(f[6], 4.0 / 16.0, kTol);
  // Centre sub-box [5,7) x [1,3): two 0.25 pixels, normalised by A/4 = 4.
  EXPECT_NEAR(f[3], 0.5 / 4.0, kTol);
  EXPECT_NEAR(f[4], 2.0 / 4.0, kTol);
  // Columns 0-1: no edges at all.
  f = extractor.Compute({0, 0, 2, 8}, 0.f);
  for (int i = 0; i < 7; ++i) EXPECT_FLOAT_EQ(f[i], 0.f) << "feature " << i;
  EXPECT_FLOAT_EQ(f[8], 0.25f);  // aspect w / h
  // One-pixel-wide box: the centre sub-box is empty, features 4-5 are 0, no division by zero.
  f = extractor.Compute({2, 0, 1, 8}, 0.f);
  EXPECT_FLOAT_EQ(f[3], 0.f);
  EXPECT_FLOAT_EQ(f[4], 0.f);
  EXPECT_FLOAT_EQ(f[6], 1.f);
}

TEST(BoxFeaturesTest, ModeTieTakesSmallestValue) {
  cv::Mat1f map(4, 4, 0.f);
  map(0, 0) = 0.3f;
  map(1, 1) = 0.3f;
  map(2, 2) = 0.2f;
  map(3, 3) = 0.2f;
  map(0, 3) = 0.9f;
  const BoxFeatureExtractor extractor(map, Uniform(4, 4, {0, 0, 0}), {0, 0}, {4, 4});
  const BoxFeatureVector f = extractor.Compute({0, 0, 4, 4}, 0.f);
  EXPECT_FLOAT_EQ(f[0], 0.9f);
  EXPECT_FLOAT_EQ(f[1], 0.2f);
  EXPECT_NEAR(f[2], 2.0 / 5.0, kTol);
}

// Brute-force features 1-3 and 6-7 of a local box: a dense scan with a sort.
std::array<double, 5> DenseEdgeFeatures(const cv::Mat1f& map, const cv::Rect& r) {
  std::vector<float> values;
  double sum = 0.0;
  for (int y = r.y; y < r.y + r.height; ++y) {
    for (int x = r.x; x < r.x + r.width; ++x) {
      sum += map(y, x);
      if (map(y, x) > 0.f) values.push_back(map(y, x));
    }
  }
  if (values.empty()) return {0, 0, 0, sum / r.area(), 0};
  std::sort(values.begin(), values.end());
  float mode = values[0];
  long best = 0;
  for (float v : values) {
    const long n = std::count(values.begin(), values.end(), v);
    if (n > best) best = n, mode = v;  // ascending scan keeps the smallest value on ties
  }
  return {values.back(), mode, static_cast<double>(best) / values.size(), sum / r.area(),
          static_cast<double>(values.size()) / r.area()};
}

TEST(BoxFeaturesTest, SparseScanMatchesDenseReference) {
  // Few distinct values so that ties and repeated modes are common.
  cv::RNG rng(12345);
  cv::Mat1f map(23, 31);
  const float levels[] = {0.f, 0.f, 0.f, 0.1f, 0.2f, 0.3f};
  for (int y = 0; y < map.rows; ++y) {
    for (int x = 0; x < map.cols; ++x) map(y, x) = levels[rng.uniform(0, 6)];
  }
  const BoxFeatureExtractor extractor(map, Uniform(23, 31, {0, 0, 0}), {5, 7}, {50, 40});
  for (int trial = 0; trial < 300; ++trial) {
    const int w = rng.uniform(1, 12), h = rng.uniform(1, 12);
    const cv::Rect local(rng.uniform(0, map.cols - w + 1), rng.uniform(0, map.rows - h + 1), w, h);
    const BoxFeatureVector f = extractor.Compute({local.x + 5, local.y + 7, w, h}, 0.f);
    const std::array<double, 5> expected = DenseEdgeFeatures(map, local);
    ASSERT_NEAR(f[0], expected[0], kTol) << "trial " << trial;
    ASSERT_NEAR(f[1], expected[1], kTol) << "trial " << trial;
    ASSERT_NEAR(f[2], expected[2], kTol) << "trial " << trial;
    ASSERT_NEAR(f[5], expected[3], kTol) << "trial " << trial;
    ASSERT_NEAR(f[6], expected[4], kTol) << "trial " << trial;
  }
}

TEST(BoxFeaturesTest, HueStdAndHueContrastWithSurroundClippedAtBorder) {
  // Left half red (H 0), right half blue (H 2/3, bin 10).
  cv::Mat3b image = Uniform(8, 8, {0, 0, 255});
  image.colRange(4, 8).setTo(cv::Vec3b(255, 0, 0));
  const BoxFeatureExtractor extractor(cv::Mat1f(8, 8, 0.f), image, {0, 0}, {8, 8});
  // Box straddling the colours: half H=0, half H=2/3 -> population std 1/3; S, V constant.
  BoxFeatureVector f = extractor.Compute({2, 2, 4, 4}, 0.f);
  EXPECT_NEAR(f[14], 1.0 / 3.0, kTol);
  EXPECT_NEAR(f[15], 0.0, kTol);
  EXPECT_NEAR(f[16], 0.0, kTol);
  // Ring of that box is the rest of the crop: 24 red, 24 blue, box 8 red, 8 blue -> parallel.
  EXPECT_NEAR(f[17], 0.0, kTol);
  // Red box at the left border: grown box [-2,6) x [0,8) is clipped to [0,6) x [0,8), i.e.
  // 32 red + 16 blue; ring = 16 red + 16 blue; box = 16 red. Distance 1 - 1/sqrt(2).
  f = extractor.Compute({0, 2, 4, 4}, 0.f);
  EXPECT_NEAR(f[14], 0.0, kTol);
  EXPECT_NEAR(f[17], 1.0 - 1.0 / std::sqrt(2.0), kTol);
  EXPECT_NEAR(f[18], 0.0, kTol);  // S = 1 everywhere
  EXPECT_NEAR(f[19], 0.0, kTol);  // V = 1 everywhere
}

TEST(BoxFeaturesTest, SaturationAndValueContrast) {
  // Left half red (S 1, V 1), right half dark grey (H 0, S 0, V 64/255 -> bin 4).
  cv::Mat3b image = Uniform(8, 8, {0, 0, 255});
  image.colRange(4, 8).setTo(cv::Vec3b(64, 64, 64));
  const BoxFeatureExtractor extractor(cv::Mat1f(8, 8, 0.f), image, {0, 0}, {8, 8});
  const BoxFeatureVector f = extractor.Compute({0, 2, 4, 4}, 0.f);
  EXPECT_NEAR(f[17], 0.0, kTol);  // both colours have hue 0
  EXPECT_NEAR(f[18], 1.0 - 1.0 / std::sqrt(2.0), kTol);
  EXPECT_NEAR(f[19], 1.0 - 1.0 / std::sqrt(2.0), kTol);
  // Straddling box: S is 1 or 0 half/half -> std 0.5; V is 1 or 64/255 -> std (1 - 64/255)/2.
  const BoxFeatureVector g = extractor.Compute({2, 0, 4, 8}, 0.f);
  EXPECT_NEAR(g[15], 0.5, kTol);
  EXPECT_NEAR(g[16], (1.0 - 64.0 / 255.0) / 2.0, kTol);
}

TEST(BoxFeaturesTest, RegionOriginOffsetAndClipping) {
  const cv::Point origin(10, 20);
  const cv::Size image(40, 50);
  const BoxFeatureExtractor extractor(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), origin,
                                      image);
  // Full-image box (15, 20, 3, 4) = local columns 5-7, rows 0-3: the 0.25 boundary.
  BoxFeatureVector f = extractor.Compute({15, 20, 3, 4}, 0.f);
  EXPECT_FLOAT_EQ(f[0], 0.25f);
  EXPECT_NEAR(f[6], 4.0 / 12.0, kTol);
  EXPECT_NEAR(f[10], (15 + 1.5) / 40.0, kTol);
  EXPECT_NEAR(f[11], (20 + 2.0) / 50.0, kTol);
  EXPECT_NEAR(f[12], 3.0 / 40.0, kTol);
  EXPECT_NEAR(f[13], 4.0 / 50.0, kTol);
  EXPECT_NEAR(f[7], 12.0 / 2000.0, kTol);
  // Box sticking out of the crop at the top-left: clipped to local [0,4) x [0,4) first.
  f = extractor.Compute({6, 18, 8, 6}, 0.f);
  EXPECT_NEAR(f[10], (10 + 2.0) / 40.0, kTol);
  EXPECT_NEAR(f[11], (20 + 2.0) / 50.0, kTol);
  EXPECT_NEAR(f[12], 4.0 / 40.0, kTol);
  EXPECT_NEAR(f[13], 4.0 / 50.0, kTol);
  EXPECT_NEAR(f[6], 4.0 / 16.0, kTol);  // column 2 rows 0-3
  // No overlap: all zero except the objectness.
  f = extractor.Compute({0, 0, 5, 5}, 0.7f);
  for (int i = 0; i < kNumBoxFeatures; ++i) {
    EXPECT_FLOAT_EQ(f[i], i == 9 ? 0.7f : 0.f) << "feature " << i;
  }
  // Compatibility flag: region-relative centre, same normalisation.
  const BoxFeatureExtractor relative(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), origin, image,
                                     {.region_relative_centre = true});
  f = relative.Compute({15, 20, 3, 4}, 0.f);
  EXPECT_NEAR(f[10], (5 + 1.5) / 40.0, kTol);
  EXPECT_NEAR(f[11], (0 + 2.0) / 50.0, kTol);
  EXPECT_NEAR(f[12], 3.0 / 40.0, kTol);
}

// With a horizon, features 10, 12 and 13 are the centre's offset from the middle column, the width
// and the height over the centre's rows below it: the same physical position and size give the
// same values at any distance. Nothing else changes.
TEST(BoxFeaturesTest, GroundPlaneSizeDividesByTheRowsBelowTheHorizon) {
  const cv::Point origin(10, 20);
  const cv::Size image(40, 50);
  const BoxFeatureExtractor paper(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), origin, image);
  const BoxFeatureExtractor ground(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), origin, image,
                                   {.horizon_y = 12.0});
  // Centre row 20 + 2 = 22, 10 rows below the horizon.
  const BoxFeatureVector p = paper.Compute({15, 20, 3, 4}, 0.f);
  const BoxFeatureVector g = ground.Compute({15, 20, 3, 4}, 0.f);
  EXPECT_NEAR(g[10], (16.5 - 20.0) / 10.0, kTol);  // left of the middle column 20
  EXPECT_NEAR(g[12], 3.0 / 10.0, kTol);
  EXPECT_NEAR(g[13], 4.0 / 10.0, kTol);
  for (int i = 0; i < kNumBoxFeatures; ++i) {
    if (i != 10 && i != 12 && i != 13) {
      EXPECT_FLOAT_EQ(g[i], p[i]) << "feature " << i;
    }
  }
  // The divisor follows each box's own centre row.
  const BoxFeatureExtractor lower(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), origin, image,
                                  {.horizon_y = 17.0});
  EXPECT_NEAR(lower.Compute({12, 20, 4, 8}, 0.f)[13], 8.0 / 7.0, kTol);  // centre row 24
  EXPECT_NEAR(lower.Compute({12, 20, 2, 4}, 0.f)[13], 4.0 / 5.0, kTol);  // centre row 22
  // A box above the horizon divides by one row, not by zero or a negative count.
  const BoxFeatureExtractor above(ThreeBoundaryMap(), Uniform(8, 8, {0, 0, 255}), origin, image,
                                  {.horizon_y = 40.0});
  const BoxFeatureVector a = above.Compute({15, 20, 3, 4}, 0.f);
  EXPECT_FLOAT_EQ(a[10], -3.5f);
  EXPECT_FLOAT_EQ(a[12], 3.f);
  EXPECT_FLOAT_EQ(a[13], 4.f);
}

TEST(BoxFeaturesTest, ComputeAllMatchesCompute) {
  const BoxFeatureExtractor extractor(ThreeBoundaryMap(), Uniform(8, 8, {10, 200, 30}), {0, 0},
                                      {8, 8});
  const std::vector<ScoredBox> proposals = {{{0, 0, 8, 8}, 0.1f}, {{1, 2, 3, 4}, 0.9f}};
  const cv::Mat1f all = extractor.ComputeAll(proposals);
  ASSERT_EQ(all.rows, 2);
  ASSERT_EQ(all.cols, kNumBoxFeatures);
  for (int r = 0; r < 2; ++r) {
    const BoxFeatureVector f = extractor.Compute(proposals[r].box, proposals[r].score);
    for (int c = 0; c < kNumBoxFeatures; ++c) EXPECT_EQ(all(r, c), f[c]);
  }
}

// `edges` edge pixels at random places with values step, 2 step, ... levels step, on random
// colours.
struct ScatteredScene {
  cv::Mat1f map;
  cv::Mat3b bgr;
};
ScatteredScene ScatteredEdges(int rows, int cols, int edges, int levels, float step, cv::RNG& rng) {
  ScatteredScene scene{cv::Mat1f(rows, cols, 0.f), cv::Mat3b(rows, cols)};
  for (int i = 0; i < edges; ++i) {
    scene.map(rng.uniform(0, rows), rng.uniform(0, cols)) =
        step * static_cast<float>(i % levels + 1);
  }
  rng.fill(scene.bgr, cv::RNG::UNIFORM, 0, 256);
  return scene;
}

TEST(BoxFeaturesTest, ComputeAllOfScatteredBoxesKeepsInputOrder) {
  // ComputeAll visits the boxes in a spatial order; rows must still follow the input order.
  cv::RNG rng(99);
  const ScatteredScene scene = ScatteredEdges(60, 200, 400, 7, 0.1f, rng);
  const BoxFeatureExtractor extractor(scene.map, scene.bgr, {10, 20}, {300, 100});
  std::vector<ScoredBox> proposals;
  for (int i = 0; i < 300; ++i) {
    const int w = rng.uniform(1, 80), h = rng.uniform(1, 40);
    proposals.push_back({{rng.uniform(-20, 220), rng.uniform(0, 90), w, h}, 0.001f * i});
  }
  const cv::Mat1f all = extractor.ComputeAll(proposals);
  ASSERT_EQ(all.rows, static_cast<int>(proposals.size()));
  for (int r = 0; r < all.rows; ++r) {
    const BoxFeatureVector f = extractor.Compute(proposals[r].box, proposals[r].score);
    for (int c = 0; c < kNumBoxFeatures; ++c) ASSERT_EQ(all(r, c), f[c]) << r << ", " << c;
  }
}

TEST(BoxFeaturesTest, ComputeIntoWritesTheGivenRows) {
  cv::RNG rng(5);
  const ScatteredScene scene = ScatteredEdges(50, 90, 200, 5, 0.125f, rng);
  const BoxFeatureExtractor extractor(scene.map, scene.bgr, {4, 2}, {120, 60});
  std::vector<ScoredBox> proposals;
  std::vector<int> rows;
  for (int i = 0; i < 40; ++i) {
    proposals.push_back(
        {{rng.uniform(0, 90), rng.uniform(0, 50), rng.uniform(1, 60), rng.uniform(1, 40)},
         0.01f * i});
    rows.push_back(2 * (39 - i) + 1);  // reversed, odd rows only
  }
  cv::Mat1f out(81, kNumBoxFeatures, -1.f);
  extractor.ComputeInto(proposals, rows, out);
  const cv::Mat1f all = extractor.ComputeAll(proposals);
  for (int i = 0; i < 40; ++i) {
    for (int c = 0; c < kNumBoxFeatures; ++c) ASSERT_EQ(out(rows[i], c), all(i, c)) << i;
  }
  for (int r = 0; r < 81; r += 2) {
    for (int c = 0; c < kNumBoxFeatures; ++c) ASSERT_EQ(out(r, c), -1.f) << "row " << r;
  }
}

TEST(BoxFeaturesTest, InvalidInputIsAnError) {
  const cv::Mat3b colour = Uniform(8, 8, {0, 0, 0});
  auto mismatch = BoxFeatureExtractor::Create(cv::Mat1f(8, 7, 0.f), colour, {0, 0}, {8, 8});
  ASSERT_FALSE(mismatch.ok());
  EXPECT_NE(mismatch.status().message().find("region_bgr"), std::string::npos);

  auto outside = BoxFeatureExtractor::Create(cv::Mat1f(8, 8, 0.f), colour, {4, 0}, {8, 8});
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.status().message().find("inside the image"), std::string::npos);

  auto no_size = BoxFeatureExtractor::Create(cv::Mat1f(8, 8, 0.f), colour, {0, 0}, {0, 8});
  EXPECT_FALSE(no_size.ok());

  cv::Mat1f nan_map(8, 8, 0.f);
  nan_map(3, 3) = std::numeric_limits<float>::quiet_NaN();
  auto nan = BoxFeatureExtractor::Create(nan_map, colour, {0, 0}, {8, 8});
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.status().message().find("NaN"), std::string::npos);

  // The constructor path stays usable: empty extractor, zeros except objectness.
  const BoxFeatureExtractor broken(nan_map, colour, {0, 0}, {8, 8});
  EXPECT_FALSE(broken.status().ok());
  const BoxFeatureVector f = broken.Compute({0, 0, 8, 8}, 0.5f);
  for (int i = 0; i < kNumBoxFeatures; ++i) EXPECT_FLOAT_EQ(f[i], i == 9 ? 0.5f : 0.f);

  auto good = BoxFeatureExtractor::Create(cv::Mat1f(8, 8, 0.f), colour, {0, 0}, {8, 8});
  EXPECT_TRUE(good.ok());
}

// --- Fast colour classification and the shared colour tables ---------------------------------

TEST(ClassifyPixelTest, BinsEqualReferenceForEveryThirdLevel) {
  // 86^3 colours covering every channel combination of levels 0, 3, ..., 255.
  for (int b = 0; b < 256; b += 3) {
    for (int g = 0; g < 256; g += 3) {
      for (int r = 0; r < 256; r += 3) {
        const cv::Vec3b bgr(b, g, r);
        const cv::Vec3f hsv = BgrToHsv(bgr);
        const PixelColour c = ClassifyPixel(bgr[0], bgr[1], bgr[2]);
        ASSERT_EQ(c.hue_bin, HueBin(hsv[0] * 360.0)) << b << " " << g << " " << r;
        ASSERT_EQ(c.sat_bin, SatValBin(hsv[1])) << b << " " << g << " " << r;
        ASSERT_EQ(c.val_bin, SatValBin(hsv[2])) << b << " " << g << " " << r;
        const cv::Vec3f fast = HsvFromLevels(c.max_level, c.delta, c.hue_units);
        ASSERT_NEAR(fast[0], hsv[0], 1e-6);
        ASSERT_NEAR(fast[1], hsv[1], 1e-6);
        ASSERT_EQ(fast[2], hsv[2]);
      }
    }
  }
}

TEST(ClassifyPixelTest, HueExactlyOnAnEdgeFollowsTheReferenceRounding) {
  // r = 12, g = 11, b = 0: hue = 60 * 11 / 12 = 55 degrees exactly, an edge. The reference's
  // float H times 360 is 54.9999994, i.e. bin 3; the fast path must agree.
  EXPECT_EQ(HueBin(BgrToHsv({0, 11, 12})[0] * 360.0), 3);
  EXPECT_EQ(ClassifyPixel(0, 11, 12).hue_bin, 3);
  // r = 255, g = 252, b = 251: hue = 60 * 1 / 4 = 15 degrees exactly; float rounding goes up.
  EXPECT_EQ(HueBin(BgrToHsv({251, 252, 255})[0] * 360.0), 1);
  EXPECT_EQ(ClassifyPixel(251, 252, 255).hue_bin, 1);
}

cv::Mat3b RandomColours(int rows, int cols, std::uint64_t seed) {
  cv::Mat3b image(rows, cols);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

ColourHistogram BruteHistogram(const cv::Mat3b& image, const cv::Rect& r) {
  ColourHistogram hist{};
  for (int y = r.y; y < r.y + r.height; ++y) {
    for (int x = r.x; x < r.x + r.width; ++x) {
      const cv::Vec3f hsv = BgrToHsv(image(y, x));
      ++hist[HueBin(hsv[0] * 360.0)];
      ++hist[kHueBins + SatValBin(hsv[1])];
      ++hist[kHueBins + kSatValBins + SatValBin(hsv[2])];
    }
  }
  return hist;
}

TEST(ColourIntegralsTest, HistogramAndMomentsMatchBruteForce) {
  // Origin (3, 5): the crop's own borders are not on the 4-px grid, so partial cells occur.
  const cv::Mat3b image = RandomColours(37, 53, 99);
  const ColourIntegrals integrals(image, {3, 5});
  EXPECT_EQ(integrals.size(), image.size());
  cv::RNG rng(4);
  for (int trial = 0; trial < 300; ++trial) {
    const int w = rng.uniform(1, 54), h = rng.uniform(1, 38);
    const cv::Rect r(rng.uniform(0, 54 - w), rng.uniform(0, 38 - h), w, h);
    ASSERT_EQ(integrals.Histogram(r), BruteHistogram(image, r)) << "trial " << trial;
    ColourMoments expected{};
    for (int y = r.y; y < r.y + r.height; ++y) {
      for (int x = r.x; x < r.x + r.width; ++x) {
        const cv::Vec3f hsv = BgrToHsv(image(y, x));
        for (int c = 0; c < 3; ++c) {
          expected[c] += hsv[c];
          expected[3 + c] += static_cast<double>(hsv[c]) * hsv[c];
        }
      }
    }
    const ColourMoments moments = integrals.Moments(r);
    for (int k = 0; k < 6; ++k) ASSERT_NEAR(moments[k], expected[k], 1e-4) << "trial " << trial;
  }
  EXPECT_EQ(integrals.Histogram({0, 0, 0, 5}), ColourHistogram{});
}

// The pixel codes, the transpose and the cells' sums run on OpenCV's pool: one thread and four
// must give the same tables, bit for bit (each band's sums are added in the same order).
TEST(ColourIntegralsTest, OneThreadAndSeveralBuildTheSameTables) {
  const cv::Mat3b image = RandomColours(301, 419, 7);
  const int threads_before = cv::getNumThreads();
  cv::setNumThreads(1);
  const ColourIntegrals one(image, {3, 5});
  cv::setNumThreads(4);
  const ColourIntegrals four(image, {3, 5});
  cv::setNumThreads(threads_before);
  cv::RNG rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const int w = rng.uniform(1, 420), h = rng.uniform(1, 302);
    const cv::Rect r(rng.uniform(0, 420 - w), rng.uniform(0, 302 - h), w, h);
    ASSERT_EQ(one.Histogram(r), four.Histogram(r)) << "trial " << trial;
    ASSERT_EQ(one.Moments(r), four.Moments(r)) << "trial " << trial;
  }
}

TEST(ColourIntegralsTest, CountsAbove65535AreExact) {
  // The corner counts are uint16 with wrap-around: a 300 x 260 uniform crop (78000 pixels) must
  // still count every pixel, as must a rectangle of 70000 pixels.
  const ColourIntegrals integrals(Uniform(260, 300, {255, 0, 0}), {0, 0});  // blue: H bin 10
  const ColourHistogram all = integrals.Histogram({0, 0, 300, 260});
  EXPECT_EQ(all[10], 78000);
  EXPECT_EQ(all[kHueBins + 15], 78000);                // S = 1
  EXPECT_EQ(all[kHueBins + kSatValBins + 15], 78000);  // V = 1
  EXPECT_EQ(integrals.Histogram({1, 3, 280, 250})[10], 70000);
}

TEST(ColourIntegralsTest, SnapToGridUsesFullImageMultiplesOfFour) {
  // Crop at full-image (3, 5): local x = 2 is global 5 -> 4 -> local 1; local x = 40 is global
  // 43 -> 44 (ties go up) -> local 41; local y = 1 is global 6 -> 8 (tie) -> local 3;
  // local y = 20 is global 25 -> 24 -> local 19.
  const ColourIntegrals integrals(Uniform(30, 50, {0, 0, 0}), {3, 5});
  const cv::Rect bounds(0, 0, 50, 30);
  EXPECT_EQ(integrals.SnapToGrid({2, 1, 38, 19}, bounds), cv::Rect(1, 3, 40, 16));
  // Clamped to the bounds: local 0 (global 3) would go to global 4 but 49 -> global 52 -> 49.
  EXPECT_EQ(integrals.SnapToGrid({0, 0, 49, 30}, {0, 0, 49, 30}), cv::Rect(1, 0, 48, 30));
}

// --- Extractor: shared colour, snapping, wide maps ----------------------------------------------

// Smooth random colours (like a real frame at small scale) and a boundary-like edge map.
void SmoothScene(int rows, int cols, cv::Mat3b& image, cv::Mat1f& map) {
  cv::Mat3b coarse = RandomColours(rows / 12 + 2, cols / 12 + 2, 5);
  cv::resize(coarse, image, {cols, rows}, 0, 0, cv::INTER_LINEAR);
  map = cv::Mat1f(rows, cols, 0.f);
  cv::RNG rng(6);
  for (int x = 5; x < cols; x += 13) {
    for (int y = 0; y < rows; ++y) map(y, x) = 0.1f * static_cast<float>(1 + (y / 9) % 4);
  }
  for (int y = 3; y < rows; y += 11) {
    for (int x = 0; x < cols; ++x) map(y, x) = 0.25f;
  }
}

std::vector<ScoredBox> RandomBoxes(int count, cv::Rect area, int min_side, int max_side,
                                   std::uint64_t seed) {
  cv::RNG rng(seed);
  std::vector<ScoredBox> boxes;
  for (int i = 0; i < count; ++i) {
    const int w = rng.uniform(min_side, max_side + 1), h = rng.uniform(min_side, max_side + 1);
    // Some boxes stick out of the area to exercise clipping.
    boxes.push_back({{area.x + rng.uniform(-w / 2, area.width - w / 2),
                      area.y + rng.uniform(-h / 2, area.height - h / 2), w, h},
                     rng.uniform(0.f, 1.f)});
  }
  return boxes;
}

TEST(BoxFeaturesTest, SharedColourGivesTheSameFeaturesAsPerRegionColour) {
  // Frame 120 x 90; R1 = [7, 127) x [9, 99) of a 140 x 110 image; the region is a nested crop at
  // full-image (22, 17), size 70 x 50, with an edge map of its own.
  cv::Mat3b frame;
  cv::Mat1f frame_map;
  SmoothScene(110, 140, frame, frame_map);
  const cv::Rect r1(7, 9, 120, 90);
  const cv::Rect region(22, 17, 70, 50);
  const cv::Size image_size = frame.size();
  auto colour = std::make_shared<const ColourIntegrals>(frame(r1), r1.tl());
  const cv::Mat1f region_map = frame_map(region).clone();
  for (const bool exact : {true, false}) {
    // Snap from small grown boxes on so that the snapping path is exercised too.
    const BoxFeatureOptions options{.exact_contrast = exact, .contrast_snap_min_area = 0};
    const BoxFeatureExtractor per_region(region_map, frame(region), region.tl(), image_size,
                                         options);
    const BoxFeatureExtractor shared(colour, region_map, region.tl(), image_size, options);
    ASSERT_TRUE(shared.status().ok()) << shared.status().message();
    for (const ScoredBox& b : RandomBoxes(300, region, 1, 60, 8)) {
      const BoxFeatureVector a = per_region.Compute(b.box, b.score);
      const BoxFeatureVector c = shared.Compute(b.box, b.score);
      for (int i = 0; i < kNumBoxFeatures; ++i) {
        if (i >= 14 && i <= 16) {  // sums over differently placed cells: rounding only
          ASSERT_NEAR(a[i], c[i], 1e-6) << "feature " << i << " exact " << exact;
        } else {
          ASSERT_EQ(a[i], c[i]) << "feature " << i << " exact " << exact << " box " << b.box.x
                                << "," << b.box.y << " " << b.box.w << "x" << b.box.h;
        }
      }
    }
  }
}

TEST(BoxFeaturesTest, SnappedContrastIsCloseToExactOnLargeBoxes) {
  cv::Mat3b image;
  cv::Mat1f map;
  SmoothScene(240, 320, image, map);
  const BoxFeatureExtractor fast(map, image, {0, 0}, image.size());  // default: snap >= 128^2
  const BoxFeatureExtractor exact(map, image, {0, 0}, image.size(), {.exact_contrast = true});
  double largest_change = 0.0;
  for (const ScoredBox& b : RandomBoxes(200, {0, 0, 320, 240}, 64, 110, 9)) {
    const BoxFeatureVector f = fast.Compute(b.box, b.score);
    const BoxFeatureVector e = exact.Compute(b.box, b.score);
    for (int i = 0; i < 17; ++i) ASSERT_EQ(f[i], e[i]) << "feature " << i;  // not approximated
    for (int i = 17; i < 20; ++i) {
      ASSERT_NEAR(f[i], e[i], 0.03) << "feature " << i;
      largest_change = std::max(largest_change, std::abs(static_cast<double>(f[i]) - e[i]));
    }
  }
  EXPECT_GT(largest_change, 0.0);  // the snapped path did run
  // Small boxes are never snapped.
  for (const ScoredBox& b : RandomBoxes(200, {0, 0, 320, 240}, 2, 40, 10)) {
    EXPECT_EQ(fast.Compute(b.box, b.score), exact.Compute(b.box, b.score));
  }
}

// Brute-force features 1-7 of a local box (M may be negative: sums include it, counts do not).
std::array<double, 7> DenseEdgeFeatures7(const cv::Mat1f& map, const cv::Rect& r) {
  const cv::Rect inner(r.x + (r.width - r.width / 2) / 2, r.y + (r.height - r.height / 2) / 2,
                       r.width / 2, r.height / 2);
  std::vector<float> values;
  double sum = 0.0, inner_sum = 0.0, inner_count = 0.0;
  for (int y = r.y; y < r.y + r.height; ++y) {
    for (int x = r.x; x < r.x + r.width; ++x) {
      sum += map(y, x);
      if (map(y, x) > 0.f) values.push_back(map(y, x));
      if (inner.contains({x, y})) {
        inner_sum += map(y, x);
        inner_count += map(y, x) > 0.f;
      }
    }
  }
  const double area = r.area();
  std::array<double, 7> out = {
      0, 0, 0, inner_sum / (area / 4), inner_count / (area / 4), sum / area, values.size() / area};
  if (values.empty()) return out;
  std::sort(values.begin(), values.end());
  long best = 0;
  for (float v : values) {
    const long n = std::count(values.begin(), values.end(), v);
    if (n > best) best = n, out[1] = v;
  }
  out[0] = values.back();
  out[2] = static_cast<double>(best) / values.size();
  return out;
}

TEST(BoxFeaturesTest, EdgeFeaturesAcrossColumnBandsMatchDenseReference) {
  // 150 columns = three 64-column bands (the last partial); boxes up to 120 wide straddle them.
  cv::RNG rng(321);
  cv::Mat1f map(40, 150);
  const float levels[] = {0.f, 0.f, 0.f, 0.f, 0.1f, 0.2f, 0.3f, -0.2f};
  for (int y = 0; y < map.rows; ++y) {
    for (int x = 0; x < map.cols; ++x) map(y, x) = levels[rng.uniform(0, 8)];
  }
  const BoxFeatureExtractor extractor(map, Uniform(40, 150, {0, 0, 0}), {0, 0}, {150, 40});
  for (int trial = 0; trial < 300; ++trial) {
    const int w = rng.uniform(1, 121), h = rng.uniform(1, 41);
    const cv::Rect r(rng.uniform(0, 151 - w), rng.uniform(0, 41 - h), w, h);
    const BoxFeatureVector f = extractor.Compute(Box::FromRect(r), 0.f);
    const std::array<double, 7> expected = DenseEdgeFeatures7(map, r);
    for (int i = 0; i < 7; ++i) ASSERT_NEAR(f[i], expected[i], kTol) << "feature " << i;
  }
}

TEST(BoxFeaturesTest, InvalidSharedInputIsAnError) {
  const cv::Mat3b frame = Uniform(40, 60, {0, 0, 0});
  auto colour = std::make_shared<const ColourIntegrals>(frame, cv::Point(10, 10));
  auto no_colour = BoxFeatureExtractor::Create(nullptr, cv::Mat1f(8, 8, 0.f), {10, 10}, {100, 80});
  ASSERT_FALSE(no_colour.ok());
  EXPECT_NE(no_colour.status().message().find("frame_colour"), std::string::npos);
  // Region [65, 75) x [10, 18) is in the frame but not in the colour crop [10, 70) x [10, 50).
  auto outside = BoxFeatureExtractor::Create(colour, cv::Mat1f(8, 10, 0.f), {65, 10}, {100, 80});
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.status().message().find("frame_colour crop"), std::string::npos);
  auto good = BoxFeatureExtractor::Create(colour, cv::Mat1f(8, 10, 0.f), {60, 42}, {100, 80});
  EXPECT_TRUE(good.ok()) << good.status().message();
}

}  // namespace
}  // namespace tod

namespace tod {
namespace {

TEST(RoadSurroundTest, RoadPatchIsTheMiddleHalfOfTheBottomTenth) {
  EXPECT_EQ(RoadPatch({2000, 470}), cv::Rect(500, 423, 1000, 47));
  EXPECT_EQ(RoadPatch({3, 5}), cv::Rect(1, 4, 1, 1));  // at least a pixel
}

// A grey road with a green verge along its top rows: a box whose surround is road measures 0, a
// box on the verge's edge measures its surround's distance from the road's colours; the feature
// sits after the optional ones that are on.
TEST(RoadSurroundTest, ASurroundOfRoadIsZeroAVergeIsNot) {
  cv::Mat3b frame = Uniform(40, 40, {90, 90, 90});
  frame.rowRange(0, 10).setTo(cv::Vec3b(40, 160, 40));
  const auto colour = std::make_shared<const ColourIntegrals>(frame, cv::Point(0, 0));
  const cv::Mat1f map(40, 40, 0.f);
  BoxFeatureOptions options{.road_surround = true};
  ASSERT_EQ(NumBoxFeatures(options), kNumBoxFeatures + 1);
  const BoxFeatureExtractor extractor(colour, map, {0, 0}, frame.size(), options);
  ASSERT_TRUE(extractor.status().ok());
  const int index = kNumBoxFeatures;
  EXPECT_NEAR(extractor.Compute({16, 20, 6, 6}, 0.f)[index], 0.0, kTol);
  // Box rows 8-13, grown by 3: rows 5-16, of which 5-9 are green (48 of the ring's 108 pixels).
  const float verge = extractor.Compute({16, 8, 6, 6}, 0.f)[index];
  EXPECT_GT(verge, 0.1f);
  EXPECT_LT(verge, 1.f);
  // Off, nothing is written past the paper's features.
  const BoxFeatureExtractor plain(colour, map, {0, 0}, frame.size(), {});
  EXPECT_EQ(plain.Compute({16, 8, 6, 6}, 0.f)[index], 0.f);
  // After the vertical edge share when that is on too.
  options.vertical_edges = true;
  const auto vertical = std::make_shared<const VerticalEdgeIntegrals>(frame, cv::Point(0, 0));
  const BoxFeatureExtractor both(colour, map, {0, 0}, frame.size(), options, vertical);
  EXPECT_FLOAT_EQ(both.Compute({16, 8, 6, 6}, 0.f)[index + 1], verge);
}

}  // namespace
}  // namespace tod
