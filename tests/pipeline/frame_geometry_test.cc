#include "core/pipeline/frame_geometry.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tod {
namespace {

ModelBundle BundleAt2048x1024() {
  ModelBundle bundle;
  bundle.regions.image_width = 2048;
  bundle.regions.image_height = 1024;
  bundle.regions.layers = {{0, 400, 2048, 624}, {512, 450, 1024, 200}};
  SizeBand band;
  band.center_y_min = 412, band.center_y_max = 612;
  band.h_min = 10, band.h_max = 100;
  band.w_min = 20, band.w_max = 200;
  band.area_min = 100, band.area_max = 10000;
  bundle.size_filter.bands = {band};
  return bundle;
}

TEST(FrameGeometryTest, SameSizeIsUnchanged) {
  const ModelBundle bundle = BundleAt2048x1024();
  const FrameGeometry g = GeometryForFrame(bundle, 2048, 1024);
  EXPECT_EQ(g.regions.layers, bundle.regions.layers);
  EXPECT_EQ(g.size_filter.bands[0].h_max, 100);
}

TEST(FrameGeometryTest, WiderAspectScalesByWidthAndKeepsRowsAboutTheCentre) {
  const FrameMapping m = MappingForFrame(2048, 1024, 1920, 1080);
  EXPECT_DOUBLE_EQ(m.scale, 0.9375);
  EXPECT_DOUBLE_EQ(m.dx, 0.0);
  EXPECT_DOUBLE_EQ(m.dy, 60.0);
  // A square stays a square: no stretching of the aspect ratio.
  const Box square = m.Map({1024, 512, 64, 64});
  EXPECT_EQ(square.w, square.h);
  EXPECT_EQ(square.x, 960);
  EXPECT_EQ(square.y, 540);  // the image centre maps to the image centre

  const FrameGeometry g = GeometryForFrame(BundleAt2048x1024(), 1920, 1080);
  EXPECT_EQ(g.regions.image_width, 1920);
  EXPECT_EQ(g.regions.image_height, 1080);
  EXPECT_EQ(g.regions.layers[0], (Box{0, 435, 1920, 585}));   // 400*0.9375+60 = 435, clipped
  EXPECT_EQ(g.regions.layers[1], (Box{480, 481, 960, 189}));  // floor / ceil outward
  const SizeBand& b = g.size_filter.bands[0];
  EXPECT_DOUBLE_EQ(b.center_y_min, 412 * 0.9375 + 60);
  EXPECT_DOUBLE_EQ(b.h_max, 93.75);
  EXPECT_DOUBLE_EQ(b.w_max, 187.5);
  EXPECT_DOUBLE_EQ(b.area_max, 10000 * 0.9375 * 0.9375);
}

// The ground-plane features' horizon is a row of the training frame: it moves with the rows.
TEST(FrameGeometryTest, FeatureHorizonMapsLikeTheRows) {
  ModelBundle bundle = BundleAt2048x1024();
  EXPECT_FALSE(FeatureOptionsForFrame(bundle, 2048, 1024).horizon_y.has_value());
  bundle.params.box_features = {.ground_plane_size = true, .horizon_y = 397.0};
  EXPECT_DOUBLE_EQ(*FeatureOptionsForFrame(bundle, 2048, 1024).horizon_y, 397.0);
  EXPECT_DOUBLE_EQ(*FeatureOptionsForFrame(bundle, 1920, 1080).horizon_y, 397.0 * 0.9375 + 60);
  EXPECT_DOUBLE_EQ(*FeatureOptionsForFrame(bundle, 1280, 720).horizon_y,
                   397.0 * 0.625 + (360 - 0.625 * 512));
}

TEST(FrameGeometryTest, SmallerFrameScalesEverythingByOneFactor) {
  const FrameGeometry g = GeometryForFrame(BundleAt2048x1024(), 1280, 720);
  const double s = 0.625, dy = 360 - 0.625 * 512;
  EXPECT_EQ(g.regions.layers[1].x, 320);
  EXPECT_EQ(g.regions.layers[1].y, static_cast<int>(std::floor(450 * s + dy)));
  EXPECT_EQ(g.regions.layers[1].w, 640);
  EXPECT_EQ(g.regions.layers[1].h, 126);
  for (const Box& r : g.regions.layers) {
    EXPECT_GE(r.x, 0);
    EXPECT_GE(r.y, 0);
    EXPECT_LE(r.right(), 1280);
    EXPECT_LE(r.bottom(), 720);
  }
}

}  // namespace
}  // namespace tod
