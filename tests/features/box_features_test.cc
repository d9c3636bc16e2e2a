#include "core/features/box_features.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

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

}  // namespace
}  // namespace tod
