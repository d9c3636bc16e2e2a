#include "core/proposals/size_filter.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

TEST(SizeFilterTest, Laf2020PresetConvertsTheTable) {
  const SizeFilter f = SizeFilter::Laf2020();
  ASSERT_EQ(f.bands.size(), 3u);
  EXPECT_DOUBLE_EQ(f.bands[0].center_y_min, 243.0);  // 244 (1-based) - 1
  EXPECT_NEAR(f.bands[0].center_y_max, 439.3333, 1e-3);
  EXPECT_DOUBLE_EQ(f.bands[0].h_min, 1.0 - 20.0);
  EXPECT_DOUBLE_EQ(f.bands[0].h_max, 97.0 + 20.0);
  EXPECT_DOUBLE_EQ(f.bands[1].w_max, 677.0 + 40.0);
  EXPECT_DOUBLE_EQ(f.bands[2].area_min, 1820.0);  // no slack on the lower area bound
  EXPECT_DOUBLE_EQ(f.bands[2].area_max, 164150.0 + 60.0);
  EXPECT_DOUBLE_EQ(f.bands[2].center_y_max, 830.0);
}

TEST(SizeFilterTest, KeepHandCases) {
  const SizeFilter f = SizeFilter::Laf2020();
  // Centre y = 300 + 10 / 2 = 305 in band 1 (243, 439.33); h 10, w 20, area 200 in range.
  EXPECT_TRUE(f.Keep(Box{100, 300, 20, 10}));
  // Same band, area 5 < 10.
  EXPECT_FALSE(f.Keep(Box{100, 300, 5, 1}));
  // Band 1 h range ends at 117; centre 305 is not in band 2.
  EXPECT_FALSE(f.Keep(Box{100, 245, 20, 120}));
  // Above every band.
  EXPECT_FALSE(f.Keep(Box{100, 90, 20, 10}));
  // Band 3: centre 700, h 30, w 60, area 1800 < 1820 -> rejected; w 61 -> area 1830 kept.
  EXPECT_FALSE(f.Keep(Box{0, 685, 60, 30}));
  EXPECT_TRUE(f.Keep(Box{0, 685, 61, 30}));
  SizeFilter off = f;
  off.enabled = false;
  EXPECT_TRUE(off.Keep(Box{100, 90, 20, 10}));
  const auto kept = f.Apply({{{100, 300, 20, 10}, 0.5f}, {{100, 90, 20, 10}, 0.9f}});
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].score, 0.5f);
}

TEST(SizeFilterTest, DeriveHandCase) {
  // Centres 110, 205, 420 -> y_min 110, y_max 420, band height 103.33.
  // Band 1 (109, 213.33): A (h 20, w 10, area 200) and B (h 10, w 30, area 300).
  // Band 2 (212.33, 316.67): empty. Band 3 (315.67, 421): C (h 40, w 40, area 1600).
  const Box a{0, 100, 10, 20}, b{0, 200, 30, 10}, c{0, 400, 40, 40};
  const SizeFilter f = SizeFilter::Derive({a, b, c});
  ASSERT_EQ(f.bands.size(), 3u);
  EXPECT_DOUBLE_EQ(f.bands[0].center_y_min, 109.0);
  EXPECT_NEAR(f.bands[0].center_y_max, 213.3333, 1e-3);
  EXPECT_DOUBLE_EQ(f.bands[0].h_min, -10.0);
  EXPECT_DOUBLE_EQ(f.bands[0].h_max, 40.0);
  EXPECT_DOUBLE_EQ(f.bands[0].w_min, -10.0);
  EXPECT_DOUBLE_EQ(f.bands[0].w_max, 50.0);
  EXPECT_DOUBLE_EQ(f.bands[0].area_min, 200.0);
  EXPECT_DOUBLE_EQ(f.bands[0].area_max, 320.0);
  EXPECT_DOUBLE_EQ(f.bands[2].h_min, -20.0);
  EXPECT_DOUBLE_EQ(f.bands[2].area_max, 1660.0);
  EXPECT_DOUBLE_EQ(f.bands[2].center_y_max, 421.0);
  for (const Box& x : {a, b, c}) EXPECT_TRUE(f.Keep(x));
  EXPECT_FALSE(f.Keep(Box{0, 100, 25, 20}));  // band 1, area 500 > 320
  EXPECT_FALSE(f.Keep(Box{0, 300, 10, 10}));  // centre 305: only the empty band 2
  EXPECT_FALSE(SizeFilter::Derive({}).enabled);
  EXPECT_TRUE(SizeFilter::Derive({}).Keep(Box{0, 0, 1, 1}));
}

TEST(SizeFilterTest, JsonRoundTripAndErrors) {
  const SizeFilter f = SizeFilter::Laf2020();
  const SizeFilter g = SizeFilter::FromJson(nlohmann::json::parse(f.ToJson().dump()));
  EXPECT_EQ(g.enabled, f.enabled);
  ASSERT_EQ(g.bands.size(), f.bands.size());
  for (size_t i = 0; i < f.bands.size(); ++i) {
    EXPECT_DOUBLE_EQ(g.bands[i].center_y_min, f.bands[i].center_y_min);
    EXPECT_DOUBLE_EQ(g.bands[i].center_y_max, f.bands[i].center_y_max);
    EXPECT_DOUBLE_EQ(g.bands[i].h_min, f.bands[i].h_min);
    EXPECT_DOUBLE_EQ(g.bands[i].w_max, f.bands[i].w_max);
    EXPECT_DOUBLE_EQ(g.bands[i].area_min, f.bands[i].area_min);
    EXPECT_DOUBLE_EQ(g.bands[i].area_max, f.bands[i].area_max);
  }
  nlohmann::json missing = f.ToJson();
  missing["bands"][1].erase("h_max");
  EXPECT_THROW(SizeFilter::FromJson(missing), nlohmann::json::exception);
  EXPECT_THROW(SizeFilter::FromJson(nlohmann::json{{"enabled", true}, {"bands", 3}}),
               nlohmann::json::exception);
  EXPECT_THROW(SizeFilter::FromJson(nlohmann::json::object()), nlohmann::json::exception);
}

}  // namespace
}  // namespace tod
