#include "core/pipeline/multilayer_regions.h"

#include <gtest/gtest.h>

#include <limits>

namespace tod {
namespace {

// Four well separated groups of obstacles: near/large at the bottom ... far/small near the
// horizon, each spread horizontally.
std::vector<ObstacleFootprint> FourDistanceGroups() {
  std::vector<ObstacleFootprint> out;
  const int bottoms[4] = {950, 700, 520, 430};
  const int sizes[4] = {120, 50, 20, 8};
  const int spans[4] = {800, 500, 250, 120};
  for (int g = 0; g < 4; ++g)
    for (int i = 0; i < 6; ++i) {
      const int s = sizes[g];
      const int cx = 1024 - spans[g] + i * (2 * spans[g] / 5);
      out.push_back({Box{cx - s / 2, bottoms[g] - s, s, s}, static_cast<long long>(s) * s});
    }
  return out;
}

TEST(MultilayerRegions, DerivedLayersAreNestedAndOrderedNearToFar) {
  RegionParams params;
  params.margin_fraction = 0.0;
  auto regions = DeriveMultilayerRegions(FourDistanceGroups(), 2048, 1024, params);
  ASSERT_TRUE(regions.ok()) << regions.status().ToString();
  ASSERT_EQ(regions->num_layers(), 4);
  for (int k = 1; k < 4; ++k) {
    const Box& outer = regions->layers[k - 1];
    const Box& inner = regions->layers[k];
    EXPECT_EQ(Intersect(outer, inner), inner) << "R" << k + 1 << " not inside R" << k;
  }
  // R1 = tight box of everything; R4 = tight box of the farthest group (bottom 430, size 8).
  EXPECT_EQ(regions->layers[0].bottom(), 950);
  EXPECT_EQ(regions->layers[3].bottom(), 430);
  EXPECT_EQ(regions->layers[3].y, 422);
  EXPECT_EQ(regions->layers[3].x, 1024 - 120 - 4);
}

TEST(MultilayerRegions, SeededAndDeterministic) {
  const auto a = DeriveMultilayerRegions(FourDistanceGroups(), 2048, 1024, {});
  const auto b = DeriveMultilayerRegions(FourDistanceGroups(), 2048, 1024, {});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->layers, b->layers);
}

TEST(MultilayerRegions, TooFewObstaclesIsAnError) {
  std::vector<ObstacleFootprint> three(3, {Box{0, 0, 4, 4}, 16});
  const auto r = DeriveMultilayerRegions(three, 100, 100, {});
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("at least 4"), std::string::npos);
}

TEST(MultilayerRegions, Laf2020PresetMatchesTheShippedTable) {
  const MultilayerRegions laf = Laf2020Regions();
  ASSERT_EQ(laf.num_layers(), 4);
  // R1: x 1..1893, y 226..840 (1-based inclusive) -> x 0, y 225, 1893 x 615.
  EXPECT_EQ(laf.layers[0], (Box{0, 225, 1893, 615}));
  EXPECT_EQ(laf.layers[3], (Box{904, 373, 341, 141}));
  // Vertical ranges of §6.1 (0-based): y_1 = 839, y_2 = 711, y_3 = 652, y_4 = 513, y_5 = 373.
  EXPECT_EQ(laf.RangeLimits(), (std::vector<int>{839, 711, 652, 513, 373}));
  EXPECT_EQ(laf.LayerCount(1000, 400), 4);
  EXPECT_EQ(laf.LayerCount(10, 300), 1);
  EXPECT_EQ(laf.LayerCount(2000, 300), 0);
}

TEST(MultilayerRegions, JsonRoundTripAndValidation) {
  const MultilayerRegions laf = Laf2020Regions();
  auto back = MultilayerRegions::FromJson(laf.ToJson());
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->layers, laf.layers);
  nlohmann::json bad = laf.ToJson();
  bad["layers"][0] = {0, 0, 5000, 10};
  EXPECT_FALSE(MultilayerRegions::FromJson(bad).ok());
  EXPECT_FALSE(MultilayerRegions::FromJson(nlohmann::json::object()).ok());
  // A far side past INT_MAX (fuzz_manifest found y + h overflowing): refused, no overflow.
  bad = laf.ToJson();
  bad["layers"][3] = {904, 373, 341, std::numeric_limits<int>::max()};
  EXPECT_FALSE(MultilayerRegions::FromJson(bad).ok());
}

// Boxes reaching past INT_MAX intersect without overflow; the result fits in ints.
TEST(BoxIntersect, FarSidesPastIntMax) {
  constexpr int kMax = std::numeric_limits<int>::max();
  EXPECT_EQ(Intersect(Box{373, 373, kMax, kMax}, Box{0, 0, 2048, 1024}),
            (Box{373, 373, 1675, 651}));
  EXPECT_EQ(Intersect(Box{10, 10, kMax, kMax}, Box{20, 20, kMax, kMax}),
            (Box{20, 20, kMax - 10, kMax - 10}));
  EXPECT_TRUE(Intersect(Box{kMax, 0, kMax, 5}, Box{0, 0, 10, 5}).empty());
}

TEST(MultilayerRegions, ScaledToHalfSize) {
  const MultilayerRegions half = Laf2020Regions().ScaledTo(1024, 512);
  EXPECT_EQ(half.layers[0], (Box{0, 112, 947, 308}));
}

}  // namespace
}  // namespace tod
