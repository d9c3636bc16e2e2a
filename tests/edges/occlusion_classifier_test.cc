#include "core/edges/occlusion_classifier.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/edges/occlusion_features.h"

namespace tod {
namespace {

// The occlusion map of inputs the test knows to be valid (an error fails the test).
cv::Mat1f Painted(const OcclusionClassifier& classifier, const cv::Mat3b& image,
                  const cv::Mat1f& enhanced_edge, const Superpixels& superpixels) {
  Result<cv::Mat1f> painted = classifier.Paint(image, enhanced_edge, superpixels, {});
  EXPECT_TRUE(painted.ok()) << painted.status().ToString();
  return painted.ok() ? std::move(painted).value() : cv::Mat1f();
}

// Three vertical stripes of superpixels separated by 1-pixel boundary columns 2 and 5:
// labels per row = 1 1 0 2 2 0 3 3; Ê = 0.2 on column 2 and 0.8 on column 5.
struct StripeScene {
  cv::Mat3b image;
  cv::Mat1f edge;
  Superpixels superpixels;
};

StripeScene MakeStripes() {
  StripeScene s;
  s.superpixels.labels = cv::Mat1i(4, 8, 0);
  s.superpixels.labels.colRange(0, 2) = 1;
  s.superpixels.labels.colRange(3, 5) = 2;
  s.superpixels.labels.colRange(6, 8) = 3;
  s.superpixels.count = 3;
  s.image = cv::Mat3b(4, 8, cv::Vec3b(0, 0, 200));      // red
  s.image.colRange(3, 8).setTo(cv::Scalar(200, 0, 0));  // blue
  s.edge = cv::Mat1f(4, 8, 0.f);
  s.edge.col(2) = 0.2f;
  s.edge.col(5) = 0.8f;
  return s;
}

// Random superpixels on a random image: labels from a coarse random grid with jittered cells,
// boundaries (label 0) wherever the right or lower neighbour differs, some touching the border,
// plus a few isolated zero pixels; colours smooth per region plus noise.
StripeScene RandomScene(int rows, int cols, int seed) {
  cv::RNG rng(seed);
  StripeScene s;
  cv::Mat1i raw(rows, cols);
  const int cell = 7;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const int jx = x + ((y / 3) % 2) * 2, jy = y + ((x / 5) % 3);
      raw(y, x) = 1 + (jy / cell) * 64 + (jx / cell);
    }
  }
  cv::Mat1i labels = raw.clone();
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const bool right = x + 1 < cols && raw(y, x + 1) != raw(y, x);
      const bool down = y + 1 < rows && raw(y + 1, x) != raw(y, x);
      if (right || down || rng.uniform(0, 50) == 0) labels(y, x) = 0;
    }
  }
  // Dense ids 1..count.
  std::vector<int> dense(64 * 64 + 1, 0);
  int count = 0;
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      int& l = labels(y, x);
      if (l == 0) continue;
      if (dense[l] == 0) dense[l] = ++count;
      l = dense[l];
    }
  }
  s.superpixels.labels = labels;
  s.superpixels.count = count;
  s.image = cv::Mat3b(rows, cols);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      const int r = raw(y, x);
      s.image(y, x) = cv::Vec3b(static_cast<uchar>((r * 37 + rng.uniform(0, 30)) % 256),
                                static_cast<uchar>((r * 91 + rng.uniform(0, 30)) % 256),
                                static_cast<uchar>((r * 13 + rng.uniform(0, 30)) % 256));
    }
  }
  s.edge = cv::Mat1f(rows, cols);
  rng.fill(s.edge, cv::RNG::UNIFORM, 0.f, 1.f);
  return s;
}

// On random superpixel maps of many shapes (1-pixel-wide and 2-pixel-high ones included) the
// pairs are exactly the label pairs that meet in a boundary pixel's 3x3 neighbourhood, each
// boundary pixel lists exactly its pairs, and every feature is finite. (The optimised version was
// also checked bit for bit against the former implementation when it was written.)
TEST(OcclusionFeaturesTest, PairsAreTheLabelsMeetingAtEachBoundaryPixel) {
  for (const cv::Size size : {cv::Size(97, 61), cv::Size(8, 3), cv::Size(1, 9), cv::Size(150, 2)}) {
    const StripeScene s = RandomScene(size.height, size.width, size.area());
    const SuperpixelPairs got = ComputeSuperpixelPairs(s.image, s.edge, s.superpixels);
    const cv::Mat1i& labels = s.superpixels.labels;
    std::set<std::pair<int, int>> expected_pairs;
    std::vector<int> expected_pixels;
    for (int y = 0; y < labels.rows; ++y) {
      for (int x = 0; x < labels.cols; ++x) {
        if (labels(y, x) != 0) continue;
        std::set<int> seen;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int yy = y + dy, xx = x + dx;
            if (yy < 0 || xx < 0 || yy >= labels.rows || xx >= labels.cols) continue;
            if (labels(yy, xx) > 0) seen.insert(labels(yy, xx));
          }
        }
        if (seen.size() < 2) continue;
        const int pixel = y * labels.cols + x;
        expected_pixels.push_back(pixel);
        std::set<std::pair<int, int>> pixel_pairs;
        for (auto i = seen.begin(); i != seen.end(); ++i) {
          for (auto j = std::next(i); j != seen.end(); ++j) pixel_pairs.insert({*i, *j});
        }
        expected_pairs.insert(pixel_pairs.begin(), pixel_pairs.end());
        const size_t k = expected_pixels.size() - 1;
        ASSERT_LT(k + 1, got.pixel_offsets.size()) << size;
        std::set<std::pair<int, int>> listed;
        for (int m = got.pixel_offsets[k]; m < got.pixel_offsets[k + 1]; ++m) {
          const cv::Vec2i pair = got.pairs[got.pixel_pairs[m]];
          listed.insert({pair[0], pair[1]});
        }
        EXPECT_EQ(listed, pixel_pairs) << size << " pixel " << pixel;
      }
    }
    EXPECT_EQ(got.boundary_pixels, expected_pixels) << size;
    std::set<std::pair<int, int>> pairs;
    for (const cv::Vec2i& pair : got.pairs) {
      EXPECT_LT(pair[0], pair[1]);
      pairs.insert({pair[0], pair[1]});
    }
    EXPECT_EQ(pairs.size(), got.pairs.size()) << size << ": a pair listed twice";
    EXPECT_EQ(pairs, expected_pairs) << size;
    ASSERT_EQ(got.features.rows, static_cast<int>(got.pairs.size()));
    EXPECT_TRUE(cv::checkRange(got.features)) << size;
  }
}

TEST(OcclusionFeaturesTest, StripePairsByHand) {
  const StripeScene s = MakeStripes();
  const SuperpixelPairs pairs = ComputeSuperpixelPairs(s.image, s.edge, s.superpixels);
  ASSERT_EQ(pairs.pairs.size(), 2u);
  EXPECT_EQ(pairs.pairs[0], cv::Vec2i(1, 2));
  EXPECT_EQ(pairs.pairs[1], cv::Vec2i(2, 3));
  EXPECT_EQ(pairs.boundary_pixels.size(), 8u);

  const float* f12 = pairs.features[0];
  EXPECT_FLOAT_EQ(f12[kEdgeMean], 0.2f);
  EXPECT_FLOAT_EQ(f12[kEdgeMax], 0.2f);
  EXPECT_FLOAT_EQ(f12[kEdgeMedian], 0.2f);
  EXPECT_FLOAT_EQ(f12[kBoundaryLength], 4.f);
  EXPECT_NEAR(f12[kBoundaryOrientation], CV_PI / 2, 1e-6);  // a vertical boundary
  EXPECT_FLOAT_EQ(f12[kBoundaryY], 1.5f / 4.f);             // rows 0..3
  EXPECT_FLOAT_EQ(f12[kAreaSmaller], 8.f);
  EXPECT_FLOAT_EQ(f12[kAreaLarger], 8.f);
  EXPECT_FLOAT_EQ(f12[kVerticalOrder], 0.f);
  // Red against blue: LUV difference of the two pure colours, hue in different bins.
  cv::Mat3b two(1, 2);
  two(0, 0) = cv::Vec3b(0, 0, 200);
  two(0, 1) = cv::Vec3b(200, 0, 0);
  cv::Mat3b luv;
  cv::cvtColor(two, luv, cv::COLOR_BGR2Luv);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(f12[kLuvDiffL + c], std::abs(luv(0, 0)[c] - luv(0, 1)[c]), 1e-4) << c;
  }
  EXPECT_FLOAT_EQ(f12[kHueChi2], 1.f);
  EXPECT_FLOAT_EQ(f12[kSaturationChi2], 0.f);  // both fully saturated
  EXPECT_FLOAT_EQ(f12[kValueChi2], 0.f);       // both value 200

  const float* f23 = pairs.features[1];  // blue against blue
  EXPECT_FLOAT_EQ(f23[kEdgeMean], 0.8f);
  EXPECT_FLOAT_EQ(f23[kLuvDiffNorm], 0.f);
  EXPECT_FLOAT_EQ(f23[kHueChi2], 0.f);
}

// Texture: two regions of vertical stripes (period 4) have identical orientation histograms
// (all gradient in the horizontal bin); vertical against horizontal stripes are near-disjoint.
TEST(OcclusionFeaturesTest, TextureDistanceSeparatesStripeOrientations) {
  Superpixels sp;
  sp.labels = cv::Mat1i(12, 21, 0);
  sp.labels.colRange(0, 10) = 1;
  sp.labels.colRange(11, 21) = 2;
  sp.count = 2;
  cv::Mat3b vertical(12, 21), mixed(12, 21);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 21; ++x) {
      const uchar v = (x / 2) % 2 ? 255 : 0;
      const uchar h = (y / 2) % 2 ? 255 : 0;
      vertical(y, x) = cv::Vec3b(v, v, v);
      mixed(y, x) = x <= 10 ? cv::Vec3b(v, v, v) : cv::Vec3b(h, h, h);
    }
  const cv::Mat1f edge(12, 21, 0.f);
  const SuperpixelPairs same = ComputeSuperpixelPairs(vertical, edge, sp);
  const SuperpixelPairs different = ComputeSuperpixelPairs(mixed, edge, sp);
  ASSERT_EQ(same.pairs.size(), 1u);
  ASSERT_EQ(different.pairs.size(), 1u);
  EXPECT_FLOAT_EQ(same.features(0, kTextureChi2), 0.f);
  EXPECT_GT(different.features(0, kTextureChi2), 0.8f);
}

TEST(OcclusionFeaturesTest, ChiSquaredByHand) {
  const float p[] = {0.5f, 0.5f, 0.f};
  const float q[] = {0.f, 0.5f, 0.5f};
  // 0.5 · (0.25/0.5 + 0 + 0.25/0.5) = 0.5
  EXPECT_FLOAT_EQ(ChiSquaredDistance(p, q, 3), 0.5f);
  EXPECT_FLOAT_EQ(ChiSquaredDistance(p, p, 3), 0.f);
}

TEST(OcclusionClassifierTest, UntrainedPaintsRescaledMeanEdge) {
  const StripeScene s = MakeStripes();
  const OcclusionClassifier classifier;
  ASSERT_FALSE(classifier.trained());
  const cv::Mat1f painted = Painted(classifier, s.image, s.edge, s.superpixels);
  ASSERT_EQ(painted.size(), s.image.size());
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 8; ++x) {
      const float expected = x == 2 ? 0.25f : (x == 5 ? 1.f : 0.f);  // 0.2 / 0.8 and 0.8 / 0.8
      EXPECT_FLOAT_EQ(painted(y, x), expected) << x << "," << y;
    }
  }
}

TEST(OcclusionClassifierTest, UntrainedFlatEdgeGivesFloor) {
  StripeScene s = MakeStripes();
  s.edge.setTo(0.f);
  const cv::Mat1f painted = Painted(OcclusionClassifier(), s.image, s.edge, s.superpixels);
  EXPECT_FLOAT_EQ(painted(0, 2), OcclusionParams{}.floor);
  EXPECT_FLOAT_EQ(painted(3, 5), OcclusionParams{}.floor);
  EXPECT_FLOAT_EQ(painted(1, 1), 0.f);
}

TEST(OcclusionClassifierTest, RejectsMismatchedInputs) {
  const StripeScene s = MakeStripes();
  const OcclusionClassifier classifier;
  const Result<cv::Mat1f> bad = classifier.Paint(s.image, cv::Mat1f(4, 7, 0.f), s.superpixels, {});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("enhanced_edge"), std::string::npos);

  Superpixels out_of_range = s.superpixels;
  out_of_range.count = 2;  // label 3 is present
  EXPECT_FALSE(classifier.Paint(s.image, s.edge, out_of_range, {}).ok());
}

// ---- Training on synthetic frames -----------------------------------------------------------

struct SyntheticFrame {
  OcclusionTrainingFrame frame;
  cv::Mat1b object_contour;   // within 1 px of an obstacle's outline
  cv::Mat1b texture_contour;  // within 1 px of a road-texture patch outline, away from obstacles
};

cv::Mat1b OutlineBand(const cv::Mat1b& mask) {
  cv::Mat1b grown, shrunk;
  cv::dilate(mask, grown, cv::Mat(), cv::Point(-1, -1), 2);
  cv::erode(mask, shrunk, cv::Mat(), cv::Point(-1, -1), 2);
  return grown & ~shrunk;
}

// Ê: gradient magnitude of the lightly blurred grey image, scaled by a fixed constant.
cv::Mat1f GradientEdge(const cv::Mat3b& image) {
  cv::Mat1b gray;
  cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  cv::Mat1f g;
  gray.convertTo(g, CV_32F, 1.0 / 255.0);
  cv::GaussianBlur(g, g, cv::Size(3, 3), 0.8);
  cv::Mat1f gx, gy, magnitude;
  cv::Sobel(g, gx, CV_32F, 1, 0);
  cv::Sobel(g, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, magnitude);
  return magnitude;
}

// Grey road (label 1) under a greenish background strip (label 0); grey texture patches on the
// road (still label 1) with MORE grey-level contrast than the saturated-colour obstacles
// (labels 2, 3, ...), so the plain edge strength alone would rank the texture higher.
SyntheticFrame MakeFrame(int seed) {
  const int width = 200, height = 120, horizon = 25;
  cv::RNG rng(seed);
  SyntheticFrame s;
  cv::Mat3b image(height, width);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int n = rng.uniform(-4, 5);
      image(y, x) =
          y < horizon ? cv::Vec3b(60 + n, 140 + n, 70 + n) : cv::Vec3b(110 + n, 110 + n, 110 + n);
    }
  cv::Mat1i labels(height, width, 1);
  labels.rowRange(0, horizon) = 0;
  cv::Mat1b texture(height, width, uchar{0}), objects(height, width, uchar{0});
  for (int i = 0; i < 4; ++i) {
    const cv::Rect patch(rng.uniform(0, width - 40), rng.uniform(horizon + 5, height - 25),
                         rng.uniform(15, 40), rng.uniform(10, 20));
    const int grey = rng.uniform(0, 2) ? 150 : 70;
    image(patch).setTo(cv::Scalar(grey, grey, grey));
    texture(patch) = 255;
  }
  const cv::Scalar colours[] = {{40, 40, 190}, {190, 60, 40}, {40, 170, 170}};
  for (int i = 0; i < 3; ++i) {
    const cv::Point centre(rng.uniform(15, width - 15), rng.uniform(horizon + 15, height - 12));
    const int radius = rng.uniform(6, 11);
    cv::Mat1b disc(height, width, uchar{0});
    cv::circle(disc, centre, radius, cv::Scalar(255), cv::FILLED);
    image.setTo(colours[i], disc);
    labels.setTo(2 + i, disc);
    objects |= disc;
  }
  s.frame.image = image;
  s.frame.enhanced_edge = GradientEdge(image);
  StickySuperpixelParams sp_params;
  sp_params.k = 256;
  Result<Superpixels> superpixels =
      ComputeStickySuperpixels(image, s.frame.enhanced_edge, sp_params);
  EXPECT_TRUE(superpixels.ok()) << superpixels.status().ToString();
  if (superpixels.ok()) s.frame.superpixels = std::move(superpixels).value();
  s.frame.labels = labels;
  cv::Mat1b near_objects;
  cv::dilate(objects, near_objects, cv::Mat(), cv::Point(-1, -1), 4);
  s.object_contour = OutlineBand(objects);
  s.texture_contour = OutlineBand(texture & ~objects) & ~near_objects;
  return s;
}

double MeanOver(const cv::Mat1f& painted, const cv::Mat1b& region, const cv::Mat1i& labels) {
  const cv::Mat1b where = region & (labels == 0);
  return cv::mean(painted, where)[0];
}

OcclusionParams SmallForest() {
  OcclusionParams params;
  params.forest.num_trees = 20;
  params.forest.threads = 1;
  params.forest.seed = 7;
  return params;
}

class TrainedOcclusionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::vector<OcclusionTrainingFrame> frames;
    for (int seed = 1; seed <= 4; ++seed) frames.push_back(MakeFrame(seed).frame);
    Result<OcclusionClassifier> fitted = OcclusionClassifier::Fit(frames, SmallForest());
    ASSERT_TRUE(fitted.ok()) << fitted.status().message();
    classifier_storage_ = std::make_unique<OcclusionClassifier>(std::move(fitted).value());
    classifier_ = classifier_storage_.get();
  }
  static void TearDownTestSuite() {
    classifier_storage_.reset();
    classifier_ = nullptr;
  }
  // Shared across the suite: training once keeps it fast.
  static std::unique_ptr<OcclusionClassifier> classifier_storage_;
  static const OcclusionClassifier* classifier_;
};
std::unique_ptr<OcclusionClassifier> TrainedOcclusionTest::classifier_storage_;
const OcclusionClassifier* TrainedOcclusionTest::classifier_ = nullptr;

TEST_F(TrainedOcclusionTest, ObjectContoursBeatRoadTexture) {
  ASSERT_TRUE(classifier_->trained());
  const SyntheticFrame test = MakeFrame(99);  // not seen in training
  const OcclusionTrainingFrame& f = test.frame;
  const cv::Mat1f painted = Painted(*classifier_, f.image, f.enhanced_edge, f.superpixels);
  const double object = MeanOver(painted, test.object_contour, f.superpixels.labels);
  const double texture = MeanOver(painted, test.texture_contour, f.superpixels.labels);
  RecordProperty("object", std::to_string(object));
  RecordProperty("texture", std::to_string(texture));
  EXPECT_GT(object, texture + 0.2) << "object " << object << " texture " << texture;

  // The untrained fallback cannot tell them apart this well: texture edges are stronger.
  const cv::Mat1f fallback =
      Painted(OcclusionClassifier(), f.image, f.enhanced_edge, f.superpixels);
  const double fallback_object = MeanOver(fallback, test.object_contour, f.superpixels.labels);
  const double fallback_texture = MeanOver(fallback, test.texture_contour, f.superpixels.labels);
  RecordProperty("fallback_object", std::to_string(fallback_object));
  RecordProperty("fallback_texture", std::to_string(fallback_texture));
  EXPECT_LT(fallback_object - fallback_texture, object - texture);
}

// The forest walks the pairs in pieces on OpenCV's threads when there are enough of them: a grid
// of 5 x 5 px superpixels (4 x 4 inside, 1 px boundaries) gives over 20 000 pairs, several pieces.
TEST_F(TrainedOcclusionTest, PaintIsTheSameOnOneThreadAndOnSeveral) {
  const SyntheticFrame test = MakeFrame(43);
  cv::Mat3b image;
  cv::resize(test.frame.image, image, cv::Size(640, 400));
  cv::Mat1f edge;
  cv::resize(test.frame.enhanced_edge, edge, image.size());
  Superpixels grid;
  grid.labels = cv::Mat1i(image.size(), 0);
  const int cols = image.cols / 5;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      if (x % 5 != 4 && y % 5 != 4) grid.labels(y, x) = 1 + (y / 5) * cols + x / 5;
  grid.count = cols * (image.rows / 5);
  // Enough pairs for three pieces of the walk (2048 pairs at least each).
  ASSERT_GT(ComputeSuperpixelPairs(image, edge, grid).pairs.size(), 20000u);
  const int threads_before = cv::getNumThreads();
  cv::setNumThreads(1);
  const cv::Mat1f one = Painted(*classifier_, image, edge, grid);
  const SuperpixelPairs pairs_one = ComputeSuperpixelPairs(image, edge, grid);
  cv::setNumThreads(3);
  const cv::Mat1f three = Painted(*classifier_, image, edge, grid);
  const SuperpixelPairs pairs_three = ComputeSuperpixelPairs(image, edge, grid);
  cv::setNumThreads(threads_before);
  // The pair features (region statistics beside the boundary scan, pairs in pieces) too.
  EXPECT_EQ(pairs_one.pairs, pairs_three.pairs);
  EXPECT_EQ(pairs_one.pixel_pairs, pairs_three.pixel_pairs);
  ASSERT_EQ(pairs_one.features.size(), pairs_three.features.size());
  EXPECT_EQ(cv::norm(pairs_one.features, pairs_three.features, cv::NORM_INF), 0.0);
  ASSERT_EQ(one.size(), image.size());
  ASSERT_EQ(three.size(), image.size());
  EXPECT_EQ(cv::countNonZero(one != three), 0);
  EXPECT_GT(cv::countNonZero(one > SmallForest().floor), 1000);  // the forest painted them
}

OcclusionPaintOptions WithDeadline(std::chrono::steady_clock::time_point deadline) {
  OcclusionPaintOptions options;
  options.deadline = deadline;
  return options;
}

// Under a frame budget the forest stops between pieces of trees: with the deadline never reached
// the map is the one without a deadline, bit for bit; with it already past, only the first
// piece (20 trees / 16 pieces -> 2 trees) is walked, every pair alike, and the map is the
// same estimate from fewer trees: a valid map that still tells contours from texture.
TEST_F(TrainedOcclusionTest, PaintStopsBetweenPiecesOfTreesAtItsDeadline) {
  using Clock = std::chrono::steady_clock;
  const SyntheticFrame test = MakeFrame(99);
  const OcclusionTrainingFrame& f = test.frame;
  const cv::Mat1f full = Painted(*classifier_, f.image, f.enhanced_edge, f.superpixels);
  int walked = -1;
  const Result<cv::Mat1f> unreached =
      classifier_->Paint(f.image, f.enhanced_edge, f.superpixels,
                         WithDeadline(Clock::now() + std::chrono::hours(1)), &walked);
  ASSERT_TRUE(unreached.ok());
  EXPECT_EQ(walked, classifier_->num_trees());
  EXPECT_EQ(cv::countNonZero(*unreached != full), 0);

  const Result<cv::Mat1f> past =
      classifier_->Paint(f.image, f.enhanced_edge, f.superpixels,
                         WithDeadline(Clock::now() - std::chrono::seconds(1)), &walked);
  ASSERT_TRUE(past.ok());
  ASSERT_EQ(classifier_->num_trees(), 20);
  EXPECT_EQ(walked, 2);
  const cv::Mat1b boundary = f.superpixels.labels == 0;
  EXPECT_EQ(cv::countNonZero((*past != 0) != boundary), 0);
  EXPECT_GT(cv::countNonZero((*past != full) & boundary), 0);
  const double object = MeanOver(*past, test.object_contour, f.superpixels.labels);
  const double texture = MeanOver(*past, test.texture_contour, f.superpixels.labels);
  EXPECT_GT(object, texture + 0.1) << "object " << object << " texture " << texture;
}

// The early exit against its reference: the map painted by hand from the pairs' screened forest
// values (RandomForest::PredictBatchScreened, itself compared with the whole walk in
// batch_prediction_test), pixel for pixel; and screening off is the plain map.
TEST_F(TrainedOcclusionTest, ScreenedPaintIsTheMapOfTheScreenedPairValues) {
  const SyntheticFrame test = MakeFrame(77);
  const OcclusionTrainingFrame& f = test.frame;
  const cv::Mat1f full = Painted(*classifier_, f.image, f.enhanced_edge, f.superpixels);
  const ForestScreening screening{.trees = 5, .final_at_most = 0.2f};
  int walked = 0;
  OcclusionPaintOptions options;
  options.screening = screening;
  const Result<cv::Mat1f> screened =
      classifier_->Paint(f.image, f.enhanced_edge, f.superpixels, options, &walked);
  ASSERT_TRUE(screened.ok());
  EXPECT_EQ(walked, classifier_->num_trees());
  const SuperpixelPairs pairs = ComputeSuperpixelPairs(f.image, f.enhanced_edge, f.superpixels);
  ForestWalkOptions walk;
  walk.screening = screening;
  const std::vector<float> values =
      classifier_->forest().PredictBatchScreened(pairs.features, walk).values;
  cv::Mat1f by_hand(f.image.size(), 0.f);
  by_hand.setTo(classifier_->params().floor, f.superpixels.labels == 0);
  for (std::size_t i = 0; i < pairs.boundary_pixels.size(); ++i) {
    float value = classifier_->params().floor;
    for (int k = pairs.pixel_offsets[i]; k < pairs.pixel_offsets[i + 1]; ++k)
      value = std::max(value, values[pairs.pixel_pairs[k]]);
    by_hand.ptr<float>(0)[pairs.boundary_pixels[i]] = value;
  }
  EXPECT_EQ(cv::countNonZero(*screened != by_hand), 0);
  EXPECT_GT(cv::countNonZero(*screened != full), 0);  // some pairs did stop early
  options.screening.trees = 0;
  const Result<cv::Mat1f> off =
      classifier_->Paint(f.image, f.enhanced_edge, f.superpixels, options);
  ASSERT_TRUE(off.ok());
  EXPECT_EQ(cv::countNonZero(*off != full), 0);
}

TEST_F(TrainedOcclusionTest, PaintOnlyOnBoundariesAndAtLeastFloor) {
  const SyntheticFrame test = MakeFrame(42);
  const OcclusionTrainingFrame& f = test.frame;
  const OcclusionClassifier fallback;
  for (const OcclusionClassifier* c : {classifier_, &fallback}) {
    const cv::Mat1f painted = Painted(*c, f.image, f.enhanced_edge, f.superpixels);
    ASSERT_EQ(painted.size(), f.image.size());
    const cv::Mat1b boundary = f.superpixels.labels == 0;
    EXPECT_EQ(cv::countNonZero((painted != 0) != boundary), 0);
    double min_on_boundary = 0.0, max_on_boundary = 0.0;
    cv::minMaxLoc(painted, &min_on_boundary, &max_on_boundary, nullptr, nullptr, boundary);
    EXPECT_GE(min_on_boundary, c->params().floor);
    EXPECT_LE(max_on_boundary, 1.0);
  }
}

TEST_F(TrainedOcclusionTest, SaveLoadRoundTrip) {
  const Result<std::string> bytes = EncodeModel(*classifier_);
  ASSERT_TRUE(bytes.ok());
  Result<OcclusionClassifier> loaded = DecodeModel<OcclusionClassifier>(*bytes, "memory");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_TRUE(loaded->trained());
  EXPECT_FLOAT_EQ(loaded->params().floor, classifier_->params().floor);
  EXPECT_EQ(loaded->params().forest.num_trees, 20);
  const SyntheticFrame test = MakeFrame(5);
  const OcclusionTrainingFrame& f = test.frame;
  const cv::Mat1f a = Painted(*classifier_, f.image, f.enhanced_edge, f.superpixels);
  const cv::Mat1f b = Painted(*loaded, f.image, f.enhanced_edge, f.superpixels);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

TEST_F(TrainedOcclusionTest, TruncatedStreamIsDataLossNamingSource) {
  const Result<std::string> saved = EncodeModel(*classifier_);
  ASSERT_TRUE(saved.ok());
  const std::string& bytes = *saved;
  for (size_t length = 0; length < bytes.size(); ++length) {
    const Result<OcclusionClassifier> loaded =
        DecodeModel<OcclusionClassifier>(std::string_view(bytes).substr(0, length), "occ.bin");
    ASSERT_FALSE(loaded.ok()) << "length " << length;
    EXPECT_EQ(loaded.status().code(), StatusCode::kDataLoss) << loaded.status().message();
    EXPECT_NE(loaded.status().message().find("occ.bin"), std::string::npos);
  }
}

TEST(OcclusionClassifierIoTest, UntrainedRoundTripAndBadMagic) {
  const Result<std::string> bytes = EncodeModel(OcclusionClassifier());
  ASSERT_TRUE(bytes.ok());
  Result<OcclusionClassifier> loaded = DecodeModel<OcclusionClassifier>(*bytes, "m");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_FALSE(loaded->trained());

  const Result<OcclusionClassifier> bad =
      DecodeModel<OcclusionClassifier>("NOTANOCCLUSIONMODEL.....", "g.bin");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("g.bin"), std::string::npos);
  EXPECT_NE(bad.status().message().find("magic"), std::string::npos);
}

TEST(OcclusionClassifierTrainTest, NoFramesIsAnError) {
  const Result<OcclusionClassifier> fitted = OcclusionClassifier::Fit({}, SmallForest());
  ASSERT_FALSE(fitted.ok());
  EXPECT_NE(fitted.status().message().find("no frames"), std::string::npos);
}

TEST(OcclusionClassifierTrainTest, FramesWithoutObstacleContoursAreAnError) {
  SyntheticFrame s = MakeFrame(3);
  s.frame.labels.setTo(1);  // one label everywhere: no contour to learn
  const Result<OcclusionClassifier> fitted = OcclusionClassifier::Fit({s.frame}, SmallForest());
  ASSERT_FALSE(fitted.ok());
  EXPECT_NE(fitted.status().message().find("no obstacle contour"), std::string::npos);
}

TEST(OcclusionClassifierTrainTest, MismatchedLabelsNameTheFrame) {
  SyntheticFrame s = MakeFrame(3);
  s.frame.labels = cv::Mat1i(10, 10, 1);
  const Result<OcclusionClassifier> fitted = OcclusionClassifier::Fit({s.frame}, SmallForest());
  ASSERT_FALSE(fitted.ok());
  EXPECT_NE(fitted.status().message().find("frame 0"), std::string::npos);
  EXPECT_NE(fitted.status().message().find("labels"), std::string::npos);
}

}  // namespace
}  // namespace tod
