#include "core/proposals/window_grid.h"

#include <gtest/gtest.h>

namespace tod {
namespace {

TEST(WindowGridTest, HandCountOnSmallMap) {
  // 16 x 12 map, min_box_area 100 (side 10), max_aspect_ratio 1 -> arRad = 0, one aspect.
  // Scales: ceil(ln(16 / 10) / ln(sqrt(1 / 0.65))) = ceil(2.18) = 3: sides 10, 12.40, 15.38
  // -> w = h = 10, 12, 15; strides floor(0.2121 * side) = 2, 2, 3.
  //   side 10: x < 16 - 10 + 2 = 8 -> 0,2,4,6 (4); y < 12 - 10 + 2 = 4 -> 0,2 (2): 8 windows
  //   side 12: x < 6 -> 0,2,4 (3); y < 2 -> 0 (1): 3 windows
  //   side 15: x < 4 -> 0,3 (2); y < 12 - 15 + 3 = 0 -> none: 0 windows
  EdgeBoxParams params;
  params.max_aspect_ratio = 1.f;
  const auto shapes = WindowShapes(16, 12, params);
  ASSERT_EQ(shapes.size(), 3u);
  EXPECT_EQ(shapes[0].width, 10);
  EXPECT_EQ(shapes[1].width, 12);
  EXPECT_EQ(shapes[2].height, 15);
  EXPECT_EQ(shapes[2].stride_y, 3);
  EXPECT_EQ(CountWindows(16, 12, params), 11);
  const std::vector<Box> grid = GenerateWindowGrid(16, 12, params);
  ASSERT_EQ(grid.size(), 11u);
  // Edge Boxes windows span [x, x + w] inclusive: the first covers 11 x 11 pixels; the last
  // 10-window at x = 6 ends at column 16, clamped to 15.
  EXPECT_EQ(grid[0], (Box{0, 0, 11, 11}));
  EXPECT_EQ(grid[7], (Box{6, 2, 10, 10}));
  EXPECT_EQ(grid[10], (Box{4, 0, 12, 12}));
}

TEST(WindowGridTest, AspectRatiosFollowTheStep) {
  // tau_a = 6: arRad = floor(ln 6 / ln(1.2692^2)) = 3 -> 7 aspects per scale; tau_a = 3 -> 5.
  EdgeBoxParams params;
  EXPECT_EQ(WindowShapes(20, 20, params).size() % 7, 0u);
  const auto shapes = WindowShapes(20, 20, params);
  // Scale 0, aspect a = 0: ar = 1.2692^-3 = 0.489, h = floor(10 / 0.489) = 20, w = 4.
  EXPECT_EQ(shapes[0].height, 20);
  EXPECT_EQ(shapes[0].width, 4);
  EXPECT_EQ(shapes[3].width, 10);  // ar = 1
  params.max_aspect_ratio = 3.f;
  EXPECT_EQ(WindowShapes(20, 20, params).size() % 5, 0u);
}

TEST(WindowGridTest, WideAspectBoundAddsOnlyWideShapes) {
  // tau_a = 6 keeps the tall side at arRad 3 (w / h down to 0.239); a wide bound of 10 gives
  // floor(ln 10 / ln(1.2692^2)) = 4 wide steps (w / h up to 1.2692^8 = 6.72): 8 aspects a scale.
  EdgeBoxParams paper;
  EdgeBoxParams wide = paper;
  wide.max_wide_aspect_ratio = 10.f;
  const auto paper_shapes = WindowShapes(40, 40, paper);
  const auto wide_shapes = WindowShapes(40, 40, wide);
  ASSERT_EQ(paper_shapes.size() % 7, 0u);
  ASSERT_EQ(wide_shapes.size() % 8, 0u);
  ASSERT_EQ(paper_shapes.size() / 7, wide_shapes.size() / 8);  // the same scales
  for (std::size_t scale = 0; scale < paper_shapes.size() / 7; ++scale) {
    // The paper's seven aspects first, in the same order, then the one wider step.
    for (std::size_t a = 0; a < 7; ++a) {
      EXPECT_EQ(wide_shapes[scale * 8 + a].width, paper_shapes[scale * 7 + a].width);
      EXPECT_EQ(wide_shapes[scale * 8 + a].height, paper_shapes[scale * 7 + a].height);
    }
    const WindowShape& widest = wide_shapes[scale * 8 + 7];
    const WindowShape& paper_widest = paper_shapes[scale * 7 + 6];
    EXPECT_GT(widest.width, paper_widest.width);
    EXPECT_LT(widest.height, paper_widest.height);
  }
  // Scale 0 (side 10): ar = 1.2692^4 = 2.595, w = floor(25.95) = 25, h = floor(3.85) = 3.
  EXPECT_EQ(wide_shapes[7].width, 25);
  EXPECT_EQ(wide_shapes[7].height, 3);
  // 0 means tau_a: the paper's grid exactly.
  wide.max_wide_aspect_ratio = 0.f;
  EXPECT_EQ(WindowShapes(40, 40, wide).size(), paper_shapes.size());
  EXPECT_EQ(CountWindows(40, 40, wide), CountWindows(40, 40, paper));
}

TEST(WindowGridTest, StrideFormulaAndFloor) {
  EdgeBoxParams params;  // (1 - 0.65) / (1 + 0.65) = 0.21212
  EXPECT_EQ(WindowStride(10, params), 2);
  EXPECT_EQ(WindowStride(30, params), 6);  // floor(6.36)
  EXPECT_EQ(WindowStride(100, params), 21);
  params.stride_factor = 0.5f;
  EXPECT_EQ(WindowStride(30, params), 3);  // floor(3.18)
  EXPECT_EQ(WindowStride(100, params), 10);
  params.stride_factor = 0.01f;
  for (int side = 1; side < 2000; side += 7) EXPECT_GE(WindowStride(side, params), 2);
  for (const WindowShape& s : WindowShapes(400, 300, params)) {
    EXPECT_EQ(s.stride_x, 2);
    EXPECT_EQ(s.stride_y, 2);
  }
}

TEST(WindowGridTest, MultistrideFactorBelowOneGivesMoreWindows) {
  EdgeBoxParams plain;
  EdgeBoxParams ms = plain;
  ms.stride_factor = 0.5f;
  const long long n_plain = CountWindows(300, 200, plain);
  const long long n_ms = CountWindows(300, 200, ms);
  EXPECT_GT(n_ms, n_plain);
  EXPECT_EQ(static_cast<long long>(GenerateWindowGrid(300, 200, ms).size()), n_ms);
  // Small windows are at the 2 px floor either way: their counts do not change.
  EXPECT_EQ(WindowStride(9, plain), WindowStride(9, ms));
}

TEST(WindowGridTest, GridBoxesStayInsideTheMap) {
  EdgeBoxParams params;
  for (const Box& b : GenerateWindowGrid(57, 23, params)) {
    EXPECT_GE(b.x, 0);
    EXPECT_GE(b.y, 0);
    EXPECT_LE(b.right(), 57);
    EXPECT_LE(b.bottom(), 23);
    EXPECT_FALSE(b.empty());
  }
  EXPECT_EQ(CountWindows(0, 10, params), 0);
  EXPECT_EQ(CountWindows(5, 5, params), 0);  // smaller than the minimum side: no scale
}

}  // namespace
}  // namespace tod
