#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/edges/edge_labels.h"
#include "core/edges/edge_pixel_features.h"
#include "core/edges/edge_source.h"

namespace tod {
namespace {

// A noisy frame with a grey background (0), a darker road in the lower part (1), two saturated
// objects (2, 3) drawn as a rectangle or an ellipse, and a void strip on top (-1).
EdgeTrainingFrame MakeFrame(int seed) {
  constexpr int kWidth = 96;
  constexpr int kHeight = 72;
  cv::RNG rng(static_cast<std::uint64_t>(seed) * 7919 + 13);
  EdgeTrainingFrame frame;
  frame.image = cv::Mat3b(kHeight, kWidth, cv::Vec3b(140, 140, 140));
  frame.labels = cv::Mat1i::zeros(kHeight, kWidth);
  const int road_top = kHeight / 2 + rng.uniform(-6, 6);
  frame.image(cv::Rect(0, road_top, kWidth, kHeight - road_top)).setTo(cv::Vec3b(80, 80, 80));
  frame.labels(cv::Rect(0, road_top, kWidth, kHeight - road_top)).setTo(1);
  const cv::Scalar palette[] = {{30, 30, 220},  {40, 200, 40},   {220, 60, 30},
                                {30, 220, 230}, {230, 230, 230}, {200, 40, 200}};
  for (int k = 0; k < 2; ++k) {
    const cv::Scalar colour = palette[rng.uniform(0, 6)];
    const cv::Point centre(rng.uniform(15, kWidth - 15), rng.uniform(15, kHeight - 15));
    const cv::Size half_axes(rng.uniform(5, 12), rng.uniform(5, 12));
    cv::Mat1b mask = cv::Mat1b::zeros(kHeight, kWidth);
    if (rng.uniform(0, 2) == 0) {
      cv::rectangle(mask, cv::Rect(centre - cv::Point(half_axes), half_axes * 2), 255, cv::FILLED);
    } else {
      cv::ellipse(mask, centre, half_axes, rng.uniform(0.0, 180.0), 0, 360, 255, cv::FILLED);
    }
    frame.image.setTo(colour, mask);
    frame.labels.setTo(2 + k, mask);
  }
  frame.labels(cv::Rect(0, 0, kWidth, 4)).setTo(kIgnoreLabel);
  cv::Mat noise(kHeight, kWidth, CV_16SC3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 8);
  cv::Mat noisy;
  frame.image.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(frame.image, CV_8UC3);  // saturating
  return frame;
}

PixelEdgeParams SmallParams() {
  PixelEdgeParams params;
  params.samples_per_frame = 800;
  params.forest.seed = 5;
  return params;
}

std::vector<EdgeTrainingFrame> TrainingFrames() {
  std::vector<EdgeTrainingFrame> frames;
  for (int seed = 0; seed < 5; ++seed) frames.push_back(MakeFrame(seed));
  return frames;
}

const PixelEdgeClassifier& Trained() {
  static const PixelEdgeClassifier classifier = [] {
    Result<PixelEdgeClassifier> trained =
        PixelEdgeClassifier::TryTrain(TrainingFrames(), SmallParams());
    EXPECT_TRUE(trained.ok()) << trained.status().message();
    return trained.ok() ? std::move(trained).value() : PixelEdgeClassifier();
  }();
  return classifier;
}

TEST(PixelFeatures, PatternSizeIsInTheIntendedRange) {
  EXPECT_EQ(NumPixelFeatures(), 13 + 8 + 8 + 8 + 12);
}

TEST(PixelEdgeClassifier, RespondsOnHeldOutContoursNotOnInteriors) {
  const PixelEdgeClassifier& classifier = Trained();
  ASSERT_TRUE(classifier.trained());
  EXPECT_EQ(classifier.kind(), EdgeKind::kPixelForest);
  for (const int seed : {100, 101, 102}) {
    const EdgeTrainingFrame held_out = MakeFrame(seed);
    const cv::Mat1f edge = classifier.Compute(held_out.image);
    ASSERT_EQ(edge.size(), held_out.image.size());
    // Contour: the boundary pixels themselves. Interior: more than 5 px from any boundary.
    const cv::Mat1b contour = NearBoundaryMask(held_out.labels, 1);
    cv::Mat1f distance;
    cv::distanceTransform(contour == 0, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const cv::Mat1b interior = (distance > 5.f) & (held_out.labels != kIgnoreLabel);
    ASSERT_GT(cv::countNonZero(contour), 50);
    ASSERT_GT(cv::countNonZero(interior), 500);
    const double contour_mean = cv::mean(edge, contour)[0];
    const double interior_mean = cv::mean(edge, interior)[0];
    EXPECT_GT(contour_mean, 2.0 * interior_mean) << "seed " << seed;
    EXPECT_GT(contour_mean, 0.5) << "seed " << seed;
    double min_value = 0.0;
    double max_value = 0.0;
    cv::minMaxLoc(edge, &min_value, &max_value);
    EXPECT_GE(min_value, 0.0);
    EXPECT_LE(max_value, 1.0);
  }
}

TEST(PixelEdgeClassifier, OddSizedCropKeepsItsSize) {
  const cv::Mat3b odd = MakeFrame(7).image(cv::Rect(3, 2, 61, 37)).clone();
  EXPECT_EQ(Trained().Compute(odd).size(), cv::Size(61, 37));
}

TEST(PixelEdgeClassifier, TinyCropsKeepTheirSize) {
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(1, 7), cv::Size(9, 1), cv::Size(3, 2)}) {
    const cv::Mat3b tiny(size, cv::Vec3b(40, 90, 200));
    EXPECT_EQ(Trained().Compute(tiny).size(), size);
    EXPECT_EQ(CreateGradientEdgeSource()->Compute(tiny).size(), size);
  }
  EXPECT_TRUE(Trained().Compute(cv::Mat3b()).empty());
}

TEST(PixelEdgeClassifier, SaveLoadRoundTripGivesIdenticalMaps) {
  const Result<std::string> bytes = EncodeModel(Trained());
  ASSERT_TRUE(bytes.ok());
  const Result<PixelEdgeClassifier> loaded = DecodeModel<PixelEdgeClassifier>(*bytes, "edges.bin");
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  const cv::Mat3b image = MakeFrame(200).image;
  EXPECT_EQ(cv::norm(Trained().Compute(image), loaded->Compute(image), cv::NORM_INF), 0.0);
}

TEST(PixelEdgeClassifier, TruncatedOrCorruptStreamsAreErrorsNamingTheSource) {
  const Result<std::string> saved = EncodeModel(Trained());
  ASSERT_TRUE(saved.ok());
  const std::string& bytes = *saved;
  for (const std::size_t length : {std::size_t{0}, std::size_t{5}, std::size_t{8}, std::size_t{20},
                                   std::size_t{32}, bytes.size() / 2, bytes.size() - 1}) {
    const Result<PixelEdgeClassifier> loaded =
        DecodeModel<PixelEdgeClassifier>(std::string_view(bytes).substr(0, length), "cut.bin");
    ASSERT_FALSE(loaded.ok()) << "length " << length;
    EXPECT_NE(loaded.status().message().find("cut.bin"), std::string::npos)
        << loaded.status().message();
  }
  std::string bad_magic = bytes;
  bad_magic[0] = 'X';
  EXPECT_EQ(DecodeModel<PixelEdgeClassifier>(bad_magic, "m.bin").status().code(),
            StatusCode::kInvalidArgument);
  std::string other_layout = bytes;
  other_layout[20] = static_cast<char>(other_layout[20] + 1);  // feature count, low byte
  EXPECT_EQ(DecodeModel<PixelEdgeClassifier>(other_layout, "l.bin").status().code(),
            StatusCode::kFailedPrecondition);
}

TEST(PixelEdgeClassifier, BadTrainingInputIsAnError) {
  const PixelEdgeParams params = SmallParams();
  EXPECT_FALSE(PixelEdgeClassifier::TryTrain({}, params).ok());

  EdgeTrainingFrame mismatched = MakeFrame(1);
  mismatched.labels = cv::Mat1i::zeros(10, 10);
  const auto wrong_size = PixelEdgeClassifier::TryTrain({mismatched}, params);
  ASSERT_FALSE(wrong_size.ok());
  EXPECT_NE(wrong_size.status().message().find("frame 0"), std::string::npos);

  EdgeTrainingFrame no_boundary = MakeFrame(2);
  no_boundary.labels.setTo(0);
  EXPECT_FALSE(PixelEdgeClassifier::TryTrain({no_boundary}, params).ok());

  const PixelEdgeClassifier untrained;
  EXPECT_FALSE(untrained.trained());
  EXPECT_EQ(cv::countNonZero(untrained.Compute(no_boundary.image)), 0);
  EXPECT_FALSE(EncodeModel(untrained).ok());
}

}  // namespace
}  // namespace tod
