#include "core/data/masks_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace tod {
namespace {

namespace fs = std::filesystem;

// A small dataset in the benchmark layout, written fresh for each test.
class MasksFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("tod_masks_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_ / "images");
    fs::create_directories(root_ / "labels_masks");
  }
  void TearDown() override { fs::remove_all(root_); }

  static cv::Mat3b Frame(int w, int h) {
    cv::Mat3b image(h, w, cv::Vec3b(90, 100, 110));
    cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
    return image;
  }
  void WriteImage(const std::string& file, const cv::Mat3b& image) {
    ASSERT_TRUE(cv::imwrite((root_ / "images" / file).string(), image));
  }
  void WriteMask(const std::string& file, const cv::Mat1b& mask) {
    ASSERT_TRUE(cv::imwrite((root_ / "labels_masks" / file).string(), mask));
  }
  void WriteSplit(const std::string& text) { std::ofstream(root_ / "split.txt") << text; }

  fs::path root_;
};

TEST_F(MasksFixture, ReadsBothMaskNamesJpegAndWebpFramesOfAnySize) {
  // Frame "2": 1280 x 720 JPEG, one obstacle, void border, a 4-pixel speck.
  cv::Mat1b mask2(72, 128, uchar{0});
  mask2(cv::Rect(10, 20, 8, 6)).setTo(1);
  mask2(cv::Rect(0, 66, 128, 6)).setTo(255);
  mask2(cv::Rect(100, 5, 2, 2)).setTo(1);
  WriteImage("2.jpg", Frame(128, 72));
  WriteMask("2.png", mask2);
  // Frame "10": 192 x 108 WebP, mask named <stem>_labels_semantic.png, no obstacle.
  WriteImage("10.webp", Frame(192, 108));
  WriteMask("10_labels_semantic.png", cv::Mat1b(108, 192, uchar{0}));

  auto dataset = OpenMasksDataset(root_.string(), "test");
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  ASSERT_EQ((*dataset)->size(), 2u);
  EXPECT_EQ((*dataset)->name(0), "2");  // natural order: 2 before 10
  EXPECT_EQ((*dataset)->name(1), "10");

  auto with_obstacle = (*dataset)->Load(0);
  ASSERT_TRUE(with_obstacle.ok()) << with_obstacle.status().message();
  EXPECT_EQ(with_obstacle->image.size(), cv::Size(128, 72));
  EXPECT_EQ(with_obstacle->free_space, FreeSpace::kNotObstacle);
  ASSERT_EQ(with_obstacle->instances.size(), 1u);  // the speck is void, not an instance
  EXPECT_EQ(with_obstacle->instances[0].box, (Box{10, 20, 8, 6}));
  EXPECT_EQ(with_obstacle->instances[0].pixel_count(), 48);
  EXPECT_EQ(cv::countNonZero(with_obstacle->obstacle), 48);
  EXPECT_EQ(cv::countNonZero(with_obstacle->ignore), 128 * 6 + 4);
  EXPECT_EQ(cv::countNonZero(with_obstacle->road), 128 * 72 - 48 - 128 * 6 - 4);
  // Road, obstacle and void partition the frame.
  EXPECT_EQ(cv::countNonZero(with_obstacle->road & with_obstacle->ignore), 0);
  EXPECT_EQ(cv::countNonZero(with_obstacle->road & with_obstacle->obstacle), 0);

  auto empty = (*dataset)->Load(1);
  ASSERT_TRUE(empty.ok()) << empty.status().message();
  EXPECT_EQ(empty->image.size(), cv::Size(192, 108));
  EXPECT_TRUE(empty->instances.empty());
  EXPECT_EQ(cv::countNonZero(empty->road), 192 * 108);
}

TEST_F(MasksFixture, EightConnectedPiecesFormOneInstance) {
  cv::Mat1b mask(40, 40, uchar{0});
  mask(cv::Rect(5, 5, 4, 4)).setTo(1);
  mask(cv::Rect(9, 9, 4, 4)).setTo(1);  // touches the first only diagonally
  auto sample = SampleFromObstacleMask(Frame(40, 40), mask, "x", "mask.png");
  ASSERT_TRUE(sample.ok());
  ASSERT_EQ(sample->instances.size(), 1u);
  EXPECT_EQ(sample->instances[0].box, (Box{5, 5, 8, 8}));
}

TEST_F(MasksFixture, RejectsValuesOutsideTheConventionNamingTheFile) {
  cv::Mat1b mask(20, 20, uchar{0});
  mask(3, 4) = 7;
  auto sample = SampleFromObstacleMask(Frame(20, 20), mask, "x", "labels_masks/x.png");
  ASSERT_FALSE(sample.ok());
  EXPECT_NE(sample.status().message().find("labels_masks/x.png"), std::string::npos);
  EXPECT_NE(sample.status().message().find("value 7"), std::string::npos);
}

TEST_F(MasksFixture, ImageWithoutMaskIsAnErrorNamingBothCandidates) {
  WriteImage("a.png", Frame(32, 32));
  auto dataset = OpenMasksDataset(root_.string(), "train");
  ASSERT_FALSE(dataset.ok());
  EXPECT_NE(dataset.status().message().find("a_labels_semantic.png"), std::string::npos);
}

TEST_F(MasksFixture, SplitFileSelectsFramesAndWithoutItEverySplitTakesAll) {
  for (const char* stem : {"0", "1", "2"}) {
    WriteImage(std::string(stem) + ".png", Frame(32, 32));
    WriteMask(std::string(stem) + ".png", cv::Mat1b(32, 32, uchar{0}));
  }
  auto all = OpenMasksDataset(root_.string(), "train");
  ASSERT_TRUE(all.ok());
  EXPECT_EQ((*all)->size(), 3u);

  WriteSplit("# dev split\ntrain 0\ntrain 2\n\ntest 1  # held out\n");
  auto train = OpenMasksDataset(root_.string(), "train");
  ASSERT_TRUE(train.ok()) << train.status().message();
  ASSERT_EQ((*train)->size(), 2u);
  EXPECT_EQ((*train)->name(1), "2");
  auto test = OpenMasksDataset(root_.string(), "test");
  ASSERT_TRUE(test.ok());
  ASSERT_EQ((*test)->size(), 1u);
  EXPECT_EQ((*test)->name(0), "1");

  // An explicit split file wins over <root>/split.txt.
  const fs::path other = root_ / "other_split.txt";
  std::ofstream(other) << "test 0\n";
  auto explicit_test = OpenMasksDataset(root_.string(), "test", other.string());
  ASSERT_TRUE(explicit_test.ok());
  ASSERT_EQ((*explicit_test)->size(), 1u);
  EXPECT_EQ((*explicit_test)->name(0), "0");

  WriteSplit("train 0\ntest 9\n");
  auto missing = OpenMasksDataset(root_.string(), "test");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("'9'"), std::string::npos);

  WriteSplit("train 0 extra\n");
  auto malformed = OpenMasksDataset(root_.string(), "train");
  ASSERT_FALSE(malformed.ok());
  EXPECT_NE(malformed.status().message().find("split.txt:1"), std::string::npos);
}

TEST_F(MasksFixture, LayoutIsRecognised) {
  EXPECT_TRUE(LooksLikeMasks(root_.string()));
  fs::remove_all(root_ / "labels_masks");
  EXPECT_FALSE(LooksLikeMasks(root_.string()));
}

}  // namespace
}  // namespace tod
