#include "core/proposals/ground_plane_size_prior.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace tod {
namespace {

// A box of physical height and width (in units of the camera height) whose centre is `d` rows
// below a horizon at row `horizon`: image size = physical size · d.
Box OnTheGround(double horizon, double d, double height, double width) {
  const int h = static_cast<int>(std::lround(height * d));
  const int w = static_cast<int>(std::lround(width * d));
  const int centre = static_cast<int>(std::lround(horizon + d));
  return Box{500 - w / 2, centre - h / 2, w, h};
}

// Obstacles of two physical sizes side by side on every 20th row from 40 to 340 rows below a
// horizon at row 200. (The fit assumes size does not change with distance: had the larger ones
// stood further away, a lower horizon would narrow the gap between the two sizes' ratios.)
std::vector<Box> TwoSizesOnAPlane() {
  std::vector<Box> boxes;
  for (double d = 40; d <= 340; d += 20) {
    boxes.push_back(OnTheGround(200, d, 0.2, 0.4));
    boxes.push_back(OnTheGround(200, d, 0.4, 0.5));
  }
  return boxes;
}

TEST(GroundPlaneSizePriorTest, FindsTheHorizonAndTheSizeRatios) {
  const auto prior = FitGroundPlaneSizePrior(TwoSizesOnAPlane());
  ASSERT_TRUE(prior.ok()) << prior.status().message();
  EXPECT_EQ(prior->obstacles, 32);
  EXPECT_NEAR(prior->horizon_y, 200.0, 2.0);
  // Pixel rounding of h, w and the centre moves the ratios by a few hundredths at d = 40.
  EXPECT_NEAR(prior->h_ratio_min, 0.2, 0.02);
  EXPECT_NEAR(prior->h_ratio_max, 0.4, 0.02);
  EXPECT_NEAR(prior->w_ratio_min, 0.4, 0.02);
  EXPECT_NEAR(prior->w_ratio_max, 0.5, 0.02);
  EXPECT_NEAR(prior->area_ratio_min, 0.08, 0.01);
  EXPECT_NEAR(prior->area_ratio_max, 0.2, 0.01);
}

TEST(GroundPlaneSizePriorTest, BandsByHand) {
  GroundPlaneSizePrior prior;
  prior.horizon_y = 100;
  prior.h_ratio_min = 0.1, prior.h_ratio_max = 0.5;
  prior.w_ratio_min = 0.2, prior.w_ratio_max = 1.0;
  prior.area_ratio_min = 0.02, prior.area_ratio_max = 0.5;
  // Centres 150 and 350: two bands (149, 250) and (249, 351).
  const std::vector<Box> boxes = {Box{0, 140, 10, 20}, Box{0, 340, 10, 20}};
  GroundPlaneSizeParams params;
  params.num_bands = 2;
  const SizeFilter f = GroundPlaneSizeFilter(prior, boxes, params);
  ASSERT_TRUE(f.enabled);
  ASSERT_EQ(f.bands.size(), 2u);
  const SizeBand& near_horizon = f.bands[0];
  EXPECT_DOUBLE_EQ(near_horizon.center_y_min, 149.0);
  EXPECT_DOUBLE_EQ(near_horizon.center_y_max, 250.0);
  // d from 49 to 150.
  EXPECT_DOUBLE_EQ(near_horizon.h_min, 0.1 * 49 - 20);
  EXPECT_DOUBLE_EQ(near_horizon.h_max, 0.5 * 150 + 20);
  EXPECT_DOUBLE_EQ(near_horizon.w_min, 0.2 * 49 - 20);
  EXPECT_DOUBLE_EQ(near_horizon.w_max, 1.0 * 150 + 20);
  EXPECT_DOUBLE_EQ(near_horizon.area_min, 0.02 * 49 * 49);
  EXPECT_DOUBLE_EQ(near_horizon.area_max, 0.5 * 150 * 150 + 20);
  const SizeBand& near_camera = f.bands[1];
  EXPECT_DOUBLE_EQ(near_camera.center_y_min, 249.0);
  EXPECT_DOUBLE_EQ(near_camera.center_y_max, 351.0);
  EXPECT_DOUBLE_EQ(near_camera.h_max, 0.5 * 251 + 20);
  EXPECT_DOUBLE_EQ(near_camera.area_min, 0.02 * 149 * 149);
}

// Every training obstacle passes the filter derived from it, whatever the boxes.
TEST(GroundPlaneSizePriorTest, KeepsEveryTrainingObstacle) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> row(300, 900), size(1, 300);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Box> boxes;
    for (int i = 0; i < 8 + trial % 40; ++i)
      boxes.push_back(Box{100, row(rng), size(rng), size(rng)});
    const auto prior = FitGroundPlaneSizePrior(boxes);
    ASSERT_TRUE(prior.ok()) << prior.status().message();
    const SizeFilter f = GroundPlaneSizeFilter(*prior, boxes);
    for (const Box& b : boxes) EXPECT_TRUE(f.Keep(b)) << "trial " << trial << " box y " << b.y;
  }
}

// The point of the prior, measured as in docs/findings.md#size-filter: obstacles of five sizes,
// each size
// at a different set of rows, left out one at a time. The filter derived from the others keeps the
// left-out obstacle when the prior is used; the authors' per-band extremes refuse an obstacle
// whenever its band held no training obstacle as large or as small.
TEST(GroundPlaneSizePriorTest, KeepsLeftOutObstaclesThatPerBandExtremesRefuse) {
  constexpr double kHeights[] = {0.1, 0.15, 0.25, 0.4, 0.6};
  std::vector<Box> boxes;
  for (int i = 0; i < 40; ++i) {
    const double height = kHeights[(i * 3) % 5];
    boxes.push_back(OnTheGround(200, 40 + 10 * i, height, 2 * height));
  }
  int kept_by_prior = 0, kept_by_bands = 0;
  for (size_t left_out = 1; left_out + 1 < boxes.size(); ++left_out) {  // inner rows only
    std::vector<Box> others = boxes;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(left_out));
    const auto prior = FitGroundPlaneSizePrior(others);
    ASSERT_TRUE(prior.ok());
    kept_by_prior += GroundPlaneSizeFilter(*prior, others).Keep(boxes[left_out]);
    kept_by_bands += SizeFilter::Derive(others).Keep(boxes[left_out]);
  }
  EXPECT_EQ(kept_by_prior, 38);
  EXPECT_LT(kept_by_bands, 36);
  // Still a filter: an obstacle far larger than any seen, or a sliver, is refused.
  const auto prior = FitGroundPlaneSizePrior(boxes);
  ASSERT_TRUE(prior.ok());
  const SizeFilter filter = GroundPlaneSizeFilter(*prior, boxes);
  EXPECT_FALSE(filter.Keep(OnTheGround(200, 300, 1.5, 3.0)));
  EXPECT_FALSE(filter.Keep(OnTheGround(200, 300, 0.01, 0.02)));
}

TEST(GroundPlaneSizePriorTest, RefusesTooFewObstaclesAndASingleRow) {
  std::vector<Box> few(7, Box{0, 100, 10, 10});
  few[3].y = 200;
  const auto too_few = FitGroundPlaneSizePrior(few);
  ASSERT_FALSE(too_few.ok());
  EXPECT_EQ(too_few.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(too_few.status().message().find("at least 8"), std::string::npos);
  const std::vector<Box> one_row(10, Box{0, 100, 10, 10});
  const auto flat = FitGroundPlaneSizePrior(one_row);
  ASSERT_FALSE(flat.ok());
  EXPECT_NE(flat.status().message().find("one row"), std::string::npos);
}

}  // namespace
}  // namespace tod
