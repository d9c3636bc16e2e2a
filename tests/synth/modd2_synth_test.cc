// The synthetic MODDv2 generator, checked through the reader: boxes round-trip exactly.
#include "core/synth/modd2_synth.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "core/modd2/modd2_ground_truth.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

class Modd2SynthTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(::testing::TempDir()) /
            ("modd2_synth_" +
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  fs::path root_;
};

TEST(Modd2SynthFrame, GroundTruthFollowsTheOfficialRules) {
  int small = 0;
  int large = 0;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    const Modd2SynthFrame frame = GenerateModd2SynthFrame(160, 120, seed);
    ASSERT_EQ(frame.image.size(), cv::Size(160, 120));
    ASSERT_EQ(frame.annotation.obstacles.size(),
              frame.small_obstacles.size() + frame.large_obstacles.size());
    const std::vector<cv::Point2d> edge = CleanSeaEdge(frame.annotation.sea_edge, 160, 120);
    const cv::Mat1b above = Modd2AboveSeaEdgeMask(edge, 160, 120);
    const cv::Mat1b water = Modd2WaterMask(edge, 160, 120);
    for (std::size_t i = 0; i < frame.annotation.obstacles.size(); ++i) {
      const Modd2PixelBox b = RoundModd2Box(frame.annotation.obstacles[i], 160, 120);
      ASSERT_TRUE(b.valid);
      const bool is_small = i < frame.small_obstacles.size();
      const Box expected = is_small ? frame.small_obstacles[i]
                                    : frame.large_obstacles[i - frame.small_obstacles.size()];
      EXPECT_EQ(b.pixels, expected) << "seed " << seed << " box " << i;
      const int above_pixels = cv::countNonZero(above(b.pixels.rect()));
      if (is_small) {
        EXPECT_EQ(above_pixels, 0);
        EXPECT_GE(b.official_area, 25);
        EXPECT_EQ(cv::countNonZero(water(b.pixels.rect())), b.pixels.area());
      } else {
        EXPECT_GT(above_pixels, 0);
      }
    }
    small += static_cast<int>(frame.small_obstacles.size());
    large += static_cast<int>(frame.large_obstacles.size());
  }
  EXPECT_GT(small, 20);  // 1..4 per frame
  EXPECT_GT(large, 5);
  // Deterministic for the seed, different across seeds.
  EXPECT_EQ(cv::countNonZero(GenerateModd2SynthFrame(160, 120, 3).image.reshape(1) !=
                             GenerateModd2SynthFrame(160, 120, 3).image.reshape(1)),
            0);
  EXPECT_GT(cv::countNonZero(GenerateModd2SynthFrame(160, 120, 3).image.reshape(1) !=
                             GenerateModd2SynthFrame(160, 120, 4).image.reshape(1)),
            0);
}

TEST(Modd2SynthFrame, SplitUsesKnownNames) {
  const Modd2Split one = Modd2SynthSplit(1);
  EXPECT_EQ(one.train.size(), 1u);
  EXPECT_TRUE(one.test.empty());
  const Modd2Split three = Modd2SynthSplit(3);
  EXPECT_EQ(three.train, std::vector<std::string>{DefaultModd2Split().train[0]});
  EXPECT_EQ(three.test,
            (std::vector<std::string>{DefaultModd2Split().test[0], DefaultModd2Split().test[1]}));
  const Modd2Split all = Modd2SynthSplit(28);
  EXPECT_EQ(all.train.size(), 8u);
  EXPECT_EQ(all.test.size(), 20u);
}

TEST_F(Modd2SynthTest, BoxesRoundTripThroughTheReader) {
  const std::uint64_t seed = 11;
  ASSERT_TRUE(WriteModd2SynthDataset(root_.string(), 3, 2, 160, 120, seed).ok());
  ASSERT_TRUE(LooksLikeModd2(root_.string()));
  const Modd2Split split = Modd2SynthSplit(3);
  std::vector<std::string> names = split.train;
  names.insert(names.end(), split.test.begin(), split.test.end());

  int checked_frames = 0;
  for (const std::string which : {"train", "test"}) {
    Result<std::unique_ptr<Dataset>> dataset = OpenModd2Dataset(root_.string(), which);
    ASSERT_TRUE(dataset.ok()) << dataset.status().message();
    ASSERT_EQ((*dataset)->size(), which == std::string("train") ? 2u : 4u);
    for (std::size_t i = 0; i < (*dataset)->size(); ++i) {
      const Result<Sample> sample = (*dataset)->Load(i);
      ASSERT_TRUE(sample.ok()) << sample.status().message();
      // "<seq>_<frame>L": find the sequence's index and the frame's offset from S.
      const std::string seq = sample->name.substr(0, 27);
      const int s = static_cast<int>(std::find(names.begin(), names.end(), seq) - names.begin());
      ASSERT_LT(s, 3);
      const long long frame_number = std::stoll(sample->name.substr(28, 8));
      const int f = static_cast<int>(frame_number - std::stoll(seq.substr(10, 8)));
      ASSERT_GE(f, 1);
      const Modd2SynthFrame expected =
          GenerateModd2SynthFrame(160, 120, Modd2SynthFrameSeed(seed, s, f));

      ASSERT_EQ(sample->image.size(), cv::Size(160, 120));
      ASSERT_EQ(sample->instances.size(), expected.small_obstacles.size()) << sample->name;
      for (std::size_t k = 0; k < expected.small_obstacles.size(); ++k) {
        EXPECT_EQ(sample->instances[k].box, expected.small_obstacles[k]) << sample->name;
        EXPECT_EQ(sample->instances[k].id, static_cast<int>(k) + 1);
      }
      for (const Box& b : expected.large_obstacles) {
        EXPECT_EQ(cv::countNonZero(sample->road(b.rect())), 0) << sample->name;
        EXPECT_EQ(cv::countNonZero(sample->obstacle(b.rect())), 0) << sample->name;
      }
      EXPECT_GT(cv::countNonZero(sample->road), 160 * 120 / 3);
      // The JPEG holds the rendered scene (up to compression).
      cv::Mat diff;
      cv::absdiff(sample->image, expected.image, diff);
      EXPECT_LT(cv::mean(diff)[0], 8.0) << sample->name;
      ++checked_frames;
    }
  }
  EXPECT_EQ(checked_frames, 6);
}

TEST_F(Modd2SynthTest, RejectsBadArguments) {
  EXPECT_EQ(WriteModd2SynthDataset(root_.string(), 0, 2, 160, 120, 1).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(WriteModd2SynthDataset(root_.string(), 29, 2, 160, 120, 1).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(WriteModd2SynthDataset(root_.string(), 2, 2, 32, 120, 1).code(),
            StatusCode::kInvalidArgument);
  // Three sequences include seq10 (E - S = 110 frames).
  const Status too_long = WriteModd2SynthDataset(root_.string(), 3, 111, 160, 120, 1);
  EXPECT_EQ(too_long.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(too_long.message().find("kope71-01-00011210-00011320"), std::string::npos)
      << too_long.message();
}

}  // namespace
}  // namespace tod
