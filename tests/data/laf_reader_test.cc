// Lost and Found reader on tiny hand-written PNG fixtures: every expected mask, box and message
// below follows from the fixture values written in this file.
#include "core/data/laf_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "tests/data/temp_dir.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

// 8 x 6 fixture (x right, y down). instanceIds:
//   row 0: ignore (0) everywhere
//   rows 1-5: road (1000), except
//     ignore id 500 at (0, 1) and (1, 1)
//     obstacle 2001 at x 2..3, y 3..4 (a full 2 x 2 block)        -> box {2, 3, 2, 2}
//     obstacle 5002 at (6, 1), (6, 2), (7, 2) (an L shape)         -> box {6, 1, 2, 2}
constexpr int kW = 8, kH = 6;

cv::Mat1w FixtureInstanceIds() {
  cv::Mat1w ids(kH, kW, static_cast<ushort>(1000));
  ids.row(0).setTo(0);
  ids(1, 0) = ids(1, 1) = 500;
  ids(cv::Rect(2, 3, 2, 2)).setTo(2001);
  ids(1, 6) = ids(2, 6) = ids(2, 7) = 5002;
  return ids;
}

// labelIds implied by the instance ids: 0 ignore, 1 road, class = id / 1000 for obstacles.
cv::Mat1b LabelIdsFor(const cv::Mat1w& ids) {
  cv::Mat1b labels(ids.size(), static_cast<uchar>(0));
  for (int y = 0; y < ids.rows; ++y) {
    for (int x = 0; x < ids.cols; ++x) {
      const int id = ids(y, x);
      labels(y, x) = id == 1000 ? 1 : id > 1000 ? static_cast<uchar>(id / 1000) : 0;
    }
  }
  return labels;
}

cv::Mat3b FixtureImage() {
  cv::Mat3b image(kH, kW);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) image(y, x) = cv::Vec3b(10 * x, 20 * y, 7 * x + 3 * y);
  }
  return image;
}

struct FramePaths {
  fs::path image, instance_ids, label_ids;
};

FramePaths WriteFrame(const fs::path& root, const std::string& split, const std::string& scene,
                      const std::string& stem, const cv::Mat3b& image, const cv::Mat& instance_ids,
                      const cv::Mat& label_ids) {
  const fs::path image_dir = root / "leftImg8bit" / split / scene;
  const fs::path gt_dir = root / "gtCoarse" / split / scene;
  fs::create_directories(image_dir);
  fs::create_directories(gt_dir);
  FramePaths p{image_dir / (stem + "_leftImg8bit.png"),
               gt_dir / (stem + "_gtCoarse_instanceIds.png"),
               gt_dir / (stem + "_gtCoarse_labelIds.png")};
  EXPECT_TRUE(cv::imwrite(p.image.string(), image));
  EXPECT_TRUE(cv::imwrite(p.instance_ids.string(), instance_ids));
  EXPECT_TRUE(cv::imwrite(p.label_ids.string(), label_ids));
  return p;
}

bool Contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

class LafReaderTest : public ::testing::Test {
 protected:
  // Frame a: the fixture above. Frame b (another scene, sorted after): road and ignore only.
  void WriteStandardFixture() {
    ids_ = FixtureInstanceIds();
    a_ = WriteFrame(dir_.path(), "test", "sceneA", "sceneA_000001_000010", FixtureImage(), ids_,
                    LabelIdsFor(ids_));
    cv::Mat1w road_only(kH, kW, static_cast<ushort>(1000));
    road_only.row(0).setTo(0);
    b_ = WriteFrame(dir_.path(), "test", "sceneB", "sceneB_000002_000020", FixtureImage(),
                    road_only, LabelIdsFor(road_only));
  }

  tod::testing::TempDir dir_;
  cv::Mat1w ids_;
  FramePaths a_, b_;
};

TEST_F(LafReaderTest, ReadsMasksAndInstancesPixelForPixel) {
  WriteStandardFixture();
  ASSERT_TRUE(LooksLikeLaf(dir_.str()));
  auto dataset = OpenLafDataset(dir_.str(), "test");
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  ASSERT_EQ((*dataset)->size(), 2u);
  EXPECT_EQ((*dataset)->name(0), "sceneA_000001_000010");
  EXPECT_EQ((*dataset)->name(1), "sceneB_000002_000020");

  auto sample = (*dataset)->Load(0);
  ASSERT_TRUE(sample.ok()) << sample.status().message();
  EXPECT_EQ(sample->name, "sceneA_000001_000010");
  EXPECT_EQ(sample->image_path, a_.image.string());
  ASSERT_EQ(sample->image.size(), cv::Size(kW, kH));
  EXPECT_EQ(cv::norm(sample->image, FixtureImage(), cv::NORM_INF), 0.0);

  // Pixel for pixel against the fixture definition.
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const int id = ids_(y, x);
      EXPECT_EQ(sample->road(y, x), id == 1000 ? 255 : 0) << x << "," << y;
      EXPECT_EQ(sample->obstacle(y, x), id > 1000 ? 255 : 0) << x << "," << y;
      EXPECT_EQ(sample->ignore(y, x), id < 1000 ? 255 : 0) << x << "," << y;
    }
  }
  // Counts by hand: ignore = 8 (row 0) + 2 = 10; obstacles 4 + 3 = 7; road = 48 - 17 = 31.
  EXPECT_EQ(cv::countNonZero(sample->ignore), 10);
  EXPECT_EQ(cv::countNonZero(sample->obstacle), 7);
  EXPECT_EQ(cv::countNonZero(sample->road), 31);

  ASSERT_EQ(sample->instances.size(), 2u);
  const ObstacleInstance& block = sample->instances[0];
  EXPECT_EQ(block.id, 2001);
  EXPECT_EQ(block.box, (Box{2, 3, 2, 2}));
  EXPECT_EQ(block.pixel_count(), 4);
  const ObstacleInstance& ell = sample->instances[1];
  EXPECT_EQ(ell.id, 5002);
  EXPECT_EQ(ell.box, (Box{6, 1, 2, 2}));
  ASSERT_EQ(ell.mask.size(), cv::Size(2, 2));
  EXPECT_EQ(ell.mask(0, 0), 255);
  EXPECT_EQ(ell.mask(0, 1), 0);  // (7, 1) is road
  EXPECT_EQ(ell.mask(1, 0), 255);
  EXPECT_EQ(ell.mask(1, 1), 255);
  EXPECT_EQ(ell.pixel_count(), 3);
}

TEST_F(LafReaderTest, KeepsFrameWithoutObstacles) {
  WriteStandardFixture();
  auto dataset = OpenLafDataset(dir_.str(), "test");
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  auto sample = (*dataset)->Load(1);
  ASSERT_TRUE(sample.ok()) << sample.status().message();
  EXPECT_TRUE(sample->instances.empty());
  EXPECT_EQ(cv::countNonZero(sample->obstacle), 0);
  EXPECT_EQ(cv::countNonZero(sample->road), kW * (kH - 1));
  EXPECT_EQ(cv::countNonZero(sample->ignore), kW);
}

TEST_F(LafReaderTest, MissingInstanceIdsFileIsNamed) {
  WriteStandardFixture();
  fs::remove(a_.instance_ids);
  auto dataset = OpenLafDataset(dir_.str(), "test");
  ASSERT_FALSE(dataset.ok());
  EXPECT_EQ(dataset.status().code(), StatusCode::kNotFound);
  EXPECT_TRUE(Contains(dataset.status().message(), a_.instance_ids.string()))
      << dataset.status().message();
}

TEST_F(LafReaderTest, FileRemovedAfterOpeningIsNamedOnLoad) {
  WriteStandardFixture();
  auto dataset = OpenLafDataset(dir_.str(), "test");
  ASSERT_TRUE(dataset.ok());
  fs::remove(a_.label_ids);
  auto sample = (*dataset)->Load(0);
  ASSERT_FALSE(sample.ok());
  EXPECT_EQ(sample.status().code(), StatusCode::kNotFound);
  EXPECT_TRUE(Contains(sample.status().message(), a_.label_ids.string()))
      << sample.status().message();
}

TEST_F(LafReaderTest, UnreadablePngIsNamed) {
  WriteStandardFixture();
  std::ofstream(a_.instance_ids, std::ios::binary | std::ios::trunc) << "this is not a PNG";
  auto dataset = OpenLafDataset(dir_.str(), "test");
  ASSERT_TRUE(dataset.ok());
  auto sample = (*dataset)->Load(0);
  ASSERT_FALSE(sample.ok());
  EXPECT_EQ(sample.status().code(), StatusCode::kDataLoss);
  EXPECT_TRUE(Contains(sample.status().message(), a_.instance_ids.string()))
      << sample.status().message();
  // The other frame is unaffected.
  EXPECT_TRUE((*dataset)->Load(1).ok());
}

TEST_F(LafReaderTest, SizeMismatchIsNamed) {
  WriteStandardFixture();
  const cv::Mat1b wrong_size(kH + 1, kW, static_cast<uchar>(1));
  ASSERT_TRUE(cv::imwrite(a_.label_ids.string(), wrong_size));
  auto dataset = OpenLafDataset(dir_.str(), "test");
  ASSERT_TRUE(dataset.ok());
  auto sample = (*dataset)->Load(0);
  ASSERT_FALSE(sample.ok());
  EXPECT_EQ(sample.status().code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(Contains(sample.status().message(), a_.label_ids.string()))
      << sample.status().message();
  EXPECT_TRUE(Contains(sample.status().message(), "8x7")) << sample.status().message();
}

TEST_F(LafReaderTest, LabelIdsDisagreementNamesTheLabelFile) {
  WriteStandardFixture();
  cv::Mat1b labels = LabelIdsFor(ids_);
  labels(5, 0) = 3;  // obstacle class on a road pixel (instanceIds says 1000 there)
  ASSERT_TRUE(cv::imwrite(a_.label_ids.string(), labels));
  auto dataset = OpenLafDataset(dir_.str(), "test");
  ASSERT_TRUE(dataset.ok());
  auto sample = (*dataset)->Load(0);
  ASSERT_FALSE(sample.ok());
  const std::string& msg = sample.status().message();
  EXPECT_TRUE(Contains(msg, a_.label_ids.string())) << msg;
  EXPECT_TRUE(Contains(msg, "x=0, y=5")) << msg;
  EXPECT_TRUE(Contains(msg, "labelIds=3")) << msg;
  EXPECT_TRUE(Contains(msg, "instanceIds=1000")) << msg;
}

TEST_F(LafReaderTest, MissingSplitDirectoryIsNamed) {
  WriteStandardFixture();
  auto dataset = OpenLafDataset(dir_.str(), "train");
  ASSERT_FALSE(dataset.ok());
  EXPECT_EQ(dataset.status().code(), StatusCode::kNotFound);
  EXPECT_TRUE(
      Contains(dataset.status().message(), (dir_.path() / "leftImg8bit" / "train").string()));
  EXPECT_FALSE(LooksLikeLaf((dir_.path() / "leftImg8bit").string()));
}

TEST(SampleFromLafAnnotation, RejectsColourInstanceImage) {
  const cv::Mat3b image(4, 4, cv::Vec3b(1, 2, 3));
  const cv::Mat3b colour_ids(4, 4, cv::Vec3b(0, 0, 0));
  const cv::Mat1b labels(4, 4, static_cast<uchar>(0));
  auto sample = SampleFromLafAnnotation(image, colour_ids, labels, "f", "frame_f");
  ASSERT_FALSE(sample.ok());
  EXPECT_EQ(sample.status().code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(Contains(sample.status().message(), "frame_f")) << sample.status().message();
}

TEST(SampleFromLafAnnotation, ObstacleWithoutMatchingLabelIsRejected) {
  // instanceIds says obstacle 2001 at one pixel, labelIds says free space (1) there.
  const cv::Mat3b image(2, 3, cv::Vec3b(0, 0, 0));
  cv::Mat1w ids(2, 3, static_cast<ushort>(1000));
  ids(1, 2) = 2001;
  const cv::Mat1b labels(2, 3, static_cast<uchar>(1));
  auto sample = SampleFromLafAnnotation(image, ids, labels, "f", "frame_f");
  ASSERT_FALSE(sample.ok());
  EXPECT_TRUE(Contains(sample.status().message(), "x=2, y=1")) << sample.status().message();
  EXPECT_TRUE(Contains(sample.status().message(), "1 pixel(s)")) << sample.status().message();
}

}  // namespace
}  // namespace tod
