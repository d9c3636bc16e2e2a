#include "core/edges/sticky_superpixels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <vector>

#include "core/edges/superpixel_boundaries.h"
#include "core/edges/superpixel_refine.h"

namespace tod {
namespace {

// The superpixels of input the test knows to be valid (an error fails the test).
Superpixels Computed(const cv::Mat3b& bgr, const cv::Mat1f& edge,
                     const StickySuperpixelParams& params = {}) {
  Result<Superpixels> sp = ComputeStickySuperpixels(bgr, edge, params);
  EXPECT_TRUE(sp.ok()) << sp.status().ToString();
  return sp.ok() ? std::move(sp).value() : Superpixels{};
}

// Uniform random colours and edges in [0, 1], and one label per pixel to start the refinement
// from: with a strong size term its labels grow freely, over many rows.
struct NoiseScene {
  cv::Mat3f colour;
  cv::Mat1f edge;
  std::vector<int> one_label_per_pixel;
  StickyImage view() const {
    return StickyImage{colour.cols, colour.rows, colour.ptr<float>(0), edge.ptr<float>(0)};
  }
};

NoiseScene MakeNoise(int width, int height, int seed) {
  NoiseScene s{cv::Mat3f(height, width), cv::Mat1f(height, width),
               std::vector<int>(static_cast<size_t>(width) * height)};
  cv::RNG rng(seed);
  rng.fill(s.colour, cv::RNG::UNIFORM, 0.f, 1.f);
  rng.fill(s.edge, cv::RNG::UNIFORM, 0.f, 1.f);
  for (size_t i = 0; i < s.one_label_per_pixel.size(); ++i)
    s.one_label_per_pixel[i] = static_cast<int>(i);
  return s;
}

// A dark disc on a flat light background; Ê = 1 on the disc's inner contour, 0 elsewhere.
struct DiscScene {
  cv::Mat3b image;
  cv::Mat1b disc;     // 255 inside
  cv::Mat1b contour;  // 255 on the disc pixels that have a 4-neighbour outside
  cv::Mat1f edge;
};

DiscScene MakeDisc(int width, int height, int radius) {
  DiscScene s;
  s.disc = cv::Mat1b(height, width, uchar{0});
  cv::circle(s.disc, {width / 2, height / 2}, radius, cv::Scalar(255), cv::FILLED);
  cv::Mat1b eroded;
  cv::erode(s.disc, eroded, cv::getStructuringElement(cv::MORPH_CROSS, {3, 3}));
  s.contour = s.disc & ~eroded;
  s.image = cv::Mat3b(height, width, cv::Vec3b(200, 200, 200));
  s.image.setTo(cv::Scalar(40, 40, 40), s.disc);
  s.edge = cv::Mat1f(height, width, 0.f);
  s.edge.setTo(1.f, s.contour);
  return s;
}

void ExpectConsecutiveLabels(const Superpixels& sp) {
  std::set<int> ids;
  for (int y = 0; y < sp.labels.rows; ++y)
    for (int x = 0; x < sp.labels.cols; ++x)
      if (sp.labels(y, x) != 0) ids.insert(sp.labels(y, x));
  ASSERT_FALSE(ids.empty());
  EXPECT_EQ(*ids.begin(), 1);
  EXPECT_EQ(*ids.rbegin(), sp.count);
  EXPECT_EQ(static_cast<int>(ids.size()), sp.count);
}

// No two different non-zero labels may touch, even diagonally.
void ExpectSeparatedByBoundaries(const cv::Mat1i& labels) {
  int violations = 0;
  for (int y = 0; y < labels.rows; ++y) {
    for (int x = 0; x < labels.cols; ++x) {
      const int a = labels(y, x);
      if (a == 0) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if (yy < 0 || xx < 0 || yy >= labels.rows || xx >= labels.cols) continue;
          const int b = labels(yy, xx);
          if (b != 0 && b != a) ++violations;
        }
    }
  }
  EXPECT_EQ(violations, 0);
}

TEST(StickySuperpixelsTest, BoundaryFollowsDiscContour) {
  const DiscScene scene = MakeDisc(160, 120, 30);
  const Superpixels sp = Computed(scene.image, scene.edge);
  ASSERT_EQ(sp.labels.size(), scene.image.size());
  ExpectConsecutiveLabels(sp);
  ExpectSeparatedByBoundaries(sp.labels);
  EXPECT_GT(sp.count, 4);

  cv::Mat1b boundary = sp.labels == 0;
  cv::Mat1b near_boundary;
  cv::dilate(boundary, near_boundary, cv::Mat());  // 3x3: within 1 px (chessboard)
  const int contour_pixels = cv::countNonZero(scene.contour);
  const int covered = cv::countNonZero(scene.contour & near_boundary);
  EXPECT_GE(covered, 0.9 * contour_pixels) << covered << " of " << contour_pixels;

  // Superpixels do not straddle the contour: pixels on the minority side of their superpixel
  // are a tiny fraction of all labelled pixels (thin slivers along the contour are allowed).
  std::vector<int> inside(sp.count + 1, 0), total(sp.count + 1, 0);
  int labelled = 0;
  for (int y = 0; y < sp.labels.rows; ++y)
    for (int x = 0; x < sp.labels.cols; ++x) {
      const int l = sp.labels(y, x);
      if (l == 0) continue;
      ++labelled;
      ++total[l];
      if (scene.disc(y, x)) ++inside[l];
    }
  int minority = 0;
  for (int l = 1; l <= sp.count; ++l) minority += std::min(inside[l], total[l] - inside[l]);
  EXPECT_LE(minority, 0.01 * labelled) << minority << " of " << labelled;
}

TEST(StickySuperpixelsTest, LargerKGivesFewerSuperpixels) {
  // A regular, mildly textured image: horizontal shading plus a fine deterministic ripple.
  cv::Mat3b image(120, 200);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const uchar v = static_cast<uchar>(100 + x / 4 + ((x * 7 + y * 13) % 11));
      image(y, x) = cv::Vec3b(v, v, v);
    }
  const cv::Mat1f edge(image.size(), 0.f);
  int previous = 0;
  for (const int k : {4096, 1024, 256}) {
    StickySuperpixelParams params;
    params.k = k;
    const Superpixels sp = Computed(image, edge, params);
    ExpectConsecutiveLabels(sp);
    EXPECT_GT(sp.count, previous) << "k=" << k;
    previous = sp.count;
  }
}

TEST(StickySuperpixelsTest, RejectsMismatchedEdgeMap) {
  const cv::Mat3b image(10, 12, cv::Vec3b(1, 2, 3));
  const cv::Mat1f edge(10, 11, 0.f);
  const Result<Superpixels> checked = ComputeStickySuperpixels(image, edge);
  ASSERT_FALSE(checked.ok());
  EXPECT_EQ(checked.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(checked.status().message().find("edge map"), std::string::npos);

  StickySuperpixelParams bad;
  bad.k = 0;
  EXPECT_FALSE(ComputeStickySuperpixels(image, cv::Mat1f(10, 12, 0.f), bad).ok());
}

TEST(StickySuperpixelsTest, TinyImagesWork) {
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(1, 7), cv::Size(5, 1), cv::Size(3, 3)}) {
    const cv::Mat3b image(size, cv::Vec3b(9, 9, 9));
    const Superpixels sp = Computed(image, cv::Mat1f(size, 0.f));
    ASSERT_EQ(sp.labels.size(), size);
    ExpectConsecutiveLabels(sp);
  }
}

TEST(StickyWeightsTest, FollowSpecification) {
  const StickyWeights w = StickyWeightsFor(1024, 0.5, 0.9);
  EXPECT_DOUBLE_EQ(w.size, 1024 * 0.5 / 1e4);
  EXPECT_DOUBLE_EQ(w.position, 0.5 / 1e4);
  EXPECT_DOUBLE_EQ(w.edge, 0.45);
  EXPECT_NEAR(w.colour, 0.05, 1e-12);
}

// One row of 4 identical pixels; with only the size term, the singleton label (cost 1/1) joins
// its 3-pixel neighbour (cost 1/(3+1)), while pixel 2 stays (1/3 < 1/(1+1)).
TEST(RefineStickyLabelsTest, SizeTermMergesSingleton) {
  const std::vector<float> colour(12, 0.5f), edge(4, 0.f);
  std::vector<int> labels = {0, 0, 0, 1};
  const StickyWeights w{.size = 1.0, .position = 0.0, .edge = 0.0, .colour = 0.0};
  const int sweeps = RefineStickyLabels({4, 1, colour.data(), edge.data()}, w, 10, labels);
  EXPECT_EQ(labels, (std::vector<int>{0, 0, 0, 0}));
  EXPECT_EQ(sweeps, 2);  // the second sweep finds no border and stops
}

// With only the edge term the label border moves next to the strong edge: pixel 2 joins label 0
// (e = 5 across its right side) instead of staying (e = 0 across its left side).
TEST(RefineStickyLabelsTest, EdgeTermSnapsBorderToEdge) {
  const std::vector<float> colour(12, 0.5f), edge = {0.f, 0.f, 0.f, 5.f};
  std::vector<int> labels = {0, 0, 1, 1};
  const StickyWeights w{.size = 0.0, .position = 0.0, .edge = 1.0, .colour = 0.0};
  RefineStickyLabels({4, 1, colour.data(), edge.data()}, w, 10, labels);
  EXPECT_EQ(labels, (std::vector<int>{0, 0, 0, 1}));
}

// The raster order on several threads runs as many sweeps at once, each a few rows behind the one
// before it. The size term grows labels over many rows, so a sweep must often wait for the ones
// ahead to leave a label alone: the labels must still be those of one thread, bit for bit.
TEST(RefineStickyLabelsTest, ChainedSweepsGiveTheLabelsOfOneThread) {
  const NoiseScene scene = MakeNoise(240, 180, 11);
  const StickyImage image = scene.view();
  const std::vector<int>& initial = scene.one_label_per_pixel;
  const int threads_before = cv::getNumThreads();
  for (const double size : {0.5, 50.0}) {
    const StickyWeights w{.size = size, .position = 1e-4, .edge = 0.1, .colour = 0.05};
    std::vector<std::vector<int>> results;
    std::vector<int> sweeps;
    for (const int threads : {1, 2, 3, 4}) {
      cv::setNumThreads(threads);
      ASSERT_EQ(cv::getNumThreads(), threads);
      for (const int iterations : {5, 8}) {
        std::vector<int> labels = initial;
        sweeps.push_back(RefineStickyLabels(image, w, iterations, labels));
        results.push_back(labels);
      }
    }
    cv::setNumThreads(threads_before);
    for (size_t r = 2; r < results.size(); ++r) {
      EXPECT_EQ(results[r], results[r % 2]) << "size " << size << ", run " << r;
      EXPECT_EQ(sweeps[r], sweeps[r % 2]) << "size " << size << ", run " << r;
    }
  }
}

// The whole stage on a textured scene: the superpixels of two threads are those of one.
TEST(StickySuperpixelsTest, TwoThreadsGiveTheSuperpixelsOfOne) {
  // The edges continue the blobs' random sequence (this scene makes the sweeps wait often).
  cv::RNG rng(4);
  cv::Mat3b blobs(24, 32), image;
  rng.fill(blobs, cv::RNG::UNIFORM, 0, 256);
  cv::resize(blobs, image, cv::Size(320, 240), 0, 0, cv::INTER_CUBIC);
  cv::Mat1f edge(image.size());
  rng.fill(edge, cv::RNG::UNIFORM, 0.f, 1.f);
  const int threads_before = cv::getNumThreads();
  cv::setNumThreads(1);
  const Superpixels one = Computed(image, edge, {});
  cv::setNumThreads(2);
  const Superpixels two = Computed(image, edge, {});
  cv::setNumThreads(threads_before);
  EXPECT_EQ(one.count, two.count);
  EXPECT_EQ(cv::countNonZero(one.labels != two.labels), 0);
}

TEST(SuperpixelBoundariesTest, StrongerEdgePixelBecomesBoundary) {
  cv::Mat1i labels(3, 6, 1);
  labels(cv::Rect(3, 0, 3, 3)) = 2;
  cv::Mat1f edge(3, 6, 0.f);
  edge.col(3) = 0.7f;  // the right side of the 2|3 pair carries the edge
  InsertSuperpixelBoundaries(edge, labels);
  const cv::Mat1i expected = (cv::Mat1i(3, 6) << 1, 1, 1, 0, 2, 2,  //
                              1, 1, 1, 0, 2, 2,                     //
                              1, 1, 1, 0, 2, 2);
  EXPECT_EQ(cv::countNonZero(labels != expected), 0) << labels;
}

TEST(SuperpixelBoundariesTest, DiagonalContactAndThinning) {
  // Label 2 occupies the bottom-right 2x2 block of a 4x4 label-1 square. Step 1 (equal edges:
  // the first pixel of each pair) marks (1,2), (1,3), (2,1), (3,1). Step 2, on that map, marks
  // (1,1) and (2,2): diagonal to the other label and not 4-enclosed. Thinning in raster order
  // returns (1,1) to label 1 (its labelled neighbours are all 1 while (2,2) is still 0); (2,2)
  // then sees both labels and stays boundary.
  cv::Mat1i labels(4, 4, 1);
  labels(cv::Rect(2, 2, 2, 2)) = 2;
  InsertSuperpixelBoundaries(cv::Mat1f(4, 4, 0.f), labels);
  const cv::Mat1i expected = (cv::Mat1i(4, 4) << 1, 1, 1, 1,  //
                              1, 1, 0, 0,                     //
                              1, 0, 0, 2,                     //
                              1, 0, 2, 2);
  EXPECT_EQ(cv::countNonZero(labels != expected), 0) << labels;
}

TEST(SuperpixelBoundariesTest, ThinningReturnsOneSidedBoundaryPixels) {
  // A 2-pixel-thick boundary column between labels 1 and 2: the left column sees only label 1
  // and returns to it; the right column then sees both and stays boundary.
  cv::Mat1i labels = (cv::Mat1i(2, 6) << 1, 1, 0, 0, 2, 2,  //
                      1, 1, 0, 0, 2, 2);
  InsertSuperpixelBoundaries(cv::Mat1f(2, 6, 0.f), labels);
  const cv::Mat1i expected = (cv::Mat1i(2, 6) << 1, 1, 1, 0, 2, 2,  //
                              1, 1, 1, 0, 2, 2);
  EXPECT_EQ(cv::countNonZero(labels != expected), 0) << labels;
}

TEST(SuperpixelBoundariesTest, RelabelSplitsDisconnectedPieces) {
  cv::Mat1i labels = (cv::Mat1i(2, 5) << 7, 7, 3, 7, 7,  //
                      7, 7, 3, 7, 9);
  EXPECT_EQ(RelabelConnectedComponents(labels), 4);
  const cv::Mat1i expected = (cv::Mat1i(2, 5) << 1, 1, 2, 3, 3,  //
                              1, 1, 2, 3, 4);
  EXPECT_EQ(cv::countNonZero(labels != expected), 0) << labels;

  cv::Mat1i sparse = (cv::Mat1i(1, 4) << 5, 0, 9, 5);
  EXPECT_EQ(CompactLabels(sparse), 2);
  EXPECT_EQ(cv::countNonZero(sparse != (cv::Mat1i(1, 4) << 1, 0, 2, 1)), 0) << sparse;
}

// The colour smoothing runs in bands of rows; its reference is one cv::sepFilter2D call over the
// whole image. A height that is no multiple of the band, and a band's worth of rows or fewer.
TEST(SmoothStickyColour, BandsGiveThePixelsOfOneFilterCall) {
  const cv::Mat1f kernel = (cv::Mat1f(1, 3) << 0.25f, 0.5f, 0.25f);
  for (const int rows : {1, 2, 63, 64, 65, 331}) {
    cv::Mat3f colour(rows, 97);
    cv::randu(colour, 0.f, 1.f);
    cv::Mat3f reference;
    cv::sepFilter2D(colour, reference, CV_32F, kernel, kernel, cv::Point(-1, -1), 0.0,
                    cv::BORDER_REFLECT);
    for (const int threads : {1, 3}) {
      cv::setNumThreads(threads);
      const cv::Mat3f banded = SmoothStickyColour(colour);
      EXPECT_EQ(cv::norm(banded, reference, cv::NORM_INF), 0.0) << rows << " rows";
    }
  }
  cv::setNumThreads(-1);
}

}  // namespace
}  // namespace tod
