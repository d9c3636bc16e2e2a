// OpenModd2Dataset on small roots in the exact MODDv2 layout.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>

#include "core/modd2/modd2_reader.h"
#include "core/modd2/modd2_split.h"
#include "tests/modd2/mat_fixture.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 40;
constexpr int kHeight = 30;

class Modd2DatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(::testing::TempDir()) /
            ("modd2_dataset_" +
             std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  static std::string Stem(long long frame) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%08lldL", frame);
    return buffer;
  }
  fs::path AnnotationPath(const std::string& seq, long long frame, bool rectified = false) const {
    return root_ / (rectified ? "annotationsV2_rectified" : "annotationsV2") / seq /
           "ground_truth" / (Stem(frame) + ".mat");
  }
  fs::path ImagePath(const std::string& seq, long long frame, bool rectified = false) const {
    return root_ / "video_data" / seq / (rectified ? "framesRectified" : "frames") /
           (Stem(frame) + ".jpg");
  }
  // Frame `frame` of `seq`: sea edge y = 10 (water = 0-based rows 10..29), one small box at
  // columns 5..11, rows 15..21 (1-based) and one large box crossing the edge.
  void AddFrame(const std::string& seq, long long frame, bool with_image = true,
                bool rectified = false) {
    const fs::path mat = AnnotationPath(seq, frame, rectified);
    fs::create_directories(mat.parent_path());
    ASSERT_TRUE(modd2_test::WriteAnnotation(mat.string(), {{1, 10}, {20, 10}, {40, 10}},
                                            {{5, 15, 6, 6}, {25, 5, 8, 8}}));
    const fs::path image = ImagePath(seq, frame, rectified);
    fs::create_directories(image.parent_path());
    if (with_image) {
      ASSERT_TRUE(cv::imwrite(image.string(), cv::Mat3b(kHeight, kWidth, cv::Vec3b(90, 60, 30))));
    }
  }
  // A sequence as in the real data: an annotation for frame S without image, then frames
  // S+1..S+count with both.
  void AddSequence(const std::string& seq, int count) {
    const long long start = std::stoll(seq.substr(10, 8));
    AddFrame(seq, start, /*with_image=*/false);
    for (int i = 1; i <= count; ++i) AddFrame(seq, start + i);
  }
  Modd2Options OneTrainSequence(const std::string& seq) const {
    Modd2Options options;
    options.train_sequences = {seq};
    return options;
  }

  fs::path root_;
};

const std::string kSeq10 = "kope71-01-00011210-00011320";
const std::string kSeq11 = "kope71-01-00011520-00011800";

TEST_F(Modd2DatasetTest, ListsFramesSPlusOneToEAndLoadsThem) {
  AddSequence(kSeq10, 2);
  AddFrame(kSeq10, 11400, /*with_image=*/false);  // beyond E: not a benchmark frame
  std::ofstream(AnnotationPath(kSeq10, 11211).parent_path() / "notes.txt") << "ignored";
  ASSERT_TRUE(LooksLikeModd2(root_.string()));
  Result<std::unique_ptr<Dataset>> dataset =
      OpenModd2Dataset(root_.string(), "train", OneTrainSequence(kSeq10));
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  const Dataset& d = **dataset;
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d.name(0), kSeq10 + "_00011211L");
  EXPECT_EQ(d.name(1), kSeq10 + "_00011212L");

  const Result<Sample> sample = d.Load(1);
  ASSERT_TRUE(sample.ok()) << sample.status().message();
  EXPECT_EQ(sample->name, kSeq10 + "_00011212L");
  EXPECT_EQ(sample->image_path, ImagePath(kSeq10, 11212).string());
  EXPECT_EQ(sample->image.size(), cv::Size(kWidth, kHeight));  // the data's own size
  ASSERT_EQ(sample->instances.size(), 1u);
  EXPECT_EQ(sample->instances[0].box, (Box{4, 14, 7, 7}));
  // Water rows 10..29 (800 px) minus the small box (49 px) and the large box's water part
  // (columns 24..32, rows 10..12: 27 px).
  EXPECT_EQ(cv::countNonZero(sample->road), 800 - 49 - 27);
  EXPECT_EQ(cv::countNonZero(sample->obstacle), 49);
  EXPECT_FALSE(d.Load(2).ok());
}

TEST_F(Modd2DatasetTest, MasksFromMatFixturesPixelForPixel) {
  // 20 x 12 frames. Frame 1: single class, uncompressed, NaN / Inf / out-of-range sea-edge
  // points (cleaned edge y = 4: water = 0-based rows 4..11) and four boxes:
  //   A [2.5 6.2 5.4 5.49] -> 0-based (2,5) 6x6, w*h = 25: kept
  //   B [11 9 2 8]         -> h capped to 3, (10,8) 3x4, w*h = 6: dropped
  //   C [9 2.6 3 3]        -> (8,2) 4x4, reaches above the edge: large
  //   D [15.2 6.5 30 7]    -> past the border, capped to (14,6) 6x6, w*h = 25: kept
  // Frames 2 and 3: obstacles stored as 0x0 and 0x4 arrays, zlib, double.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<std::vector<double>> edge = {{-3, 4}, {nan, 7}, {10, 4}, {30, 4}, {inf, 2}};
  const long long start = 11210;
  for (long long frame = start; frame <= start + 3; ++frame) {
    const fs::path mat = AnnotationPath(kSeq10, frame);
    fs::create_directories(mat.parent_path());
    if (frame == start + 1) {
      ASSERT_TRUE(modd2_test::WriteAnnotation(
          mat.string(), edge,
          {{2.5, 6.2, 5.4, 5.49}, {11, 9, 2, 8}, {9, 2.6, 3, 3}, {15.2, 6.5, 30, 7}},
          MAT_COMPRESSION_NONE, /*single=*/true));
    } else {
      ASSERT_TRUE(modd2_test::WriteStructMat(
          mat.string(), "annotations",
          {modd2_test::Matrix("sea_edge", edge),
           modd2_test::Matrix("obstacles", {}, frame == start + 2 ? 0 : 4)}));
    }
    const fs::path image = ImagePath(kSeq10, frame);
    fs::create_directories(image.parent_path());
    if (frame > start) {
      ASSERT_TRUE(cv::imwrite(image.string(), cv::Mat3b(12, 20, cv::Vec3b(0, 0, 0))));
    }
  }
  Result<std::unique_ptr<Dataset>> dataset =
      OpenModd2Dataset(root_.string(), "train", OneTrainSequence(kSeq10));
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  ASSERT_EQ((*dataset)->size(), 3u);

  const auto rects = [](const std::vector<cv::Rect>& list) {
    cv::Mat1b m(12, 20, static_cast<unsigned char>(0));
    for (const cv::Rect& r : list) m(r).setTo(255);
    return m;
  };
  const cv::Rect a(2, 5, 6, 6), b(10, 8, 3, 4), c(8, 2, 4, 4), d(14, 6, 6, 6);
  const cv::Mat1b water = rects({cv::Rect(0, 4, 20, 8)});
  const cv::Mat1b road = water & ~rects({a, b, c, d});
  const cv::Mat1b obstacle = rects({a, d});
  const Result<Sample> boxes = (*dataset)->Load(0);
  ASSERT_TRUE(boxes.ok()) << boxes.status().message();
  EXPECT_EQ(cv::countNonZero(boxes->road != road), 0);
  EXPECT_EQ(cv::countNonZero(boxes->obstacle != obstacle), 0);
  EXPECT_EQ(cv::countNonZero(boxes->ignore != ~(road | obstacle)), 0);
  ASSERT_EQ(boxes->instances.size(), 2u);
  EXPECT_EQ(boxes->instances[0].box, Box::FromRect(a));
  EXPECT_EQ(boxes->instances[1].box, Box::FromRect(d));
  for (std::size_t i = 1; i <= 2; ++i) {
    const Result<Sample> empty = (*dataset)->Load(i);
    ASSERT_TRUE(empty.ok()) << empty.status().message();
    EXPECT_TRUE(empty->instances.empty());
    EXPECT_EQ(cv::countNonZero(empty->road != water), 0);
    EXPECT_EQ(cv::countNonZero(empty->ignore != ~water), 0);
  }
}

TEST_F(Modd2DatasetTest, FrameWithoutImage) {
  AddSequence(kSeq10, 2);
  fs::remove(ImagePath(kSeq10, 11212));
  const Result<std::unique_ptr<Dataset>> dataset =
      OpenModd2Dataset(root_.string(), "train", OneTrainSequence(kSeq10));
  ASSERT_FALSE(dataset.ok());
  EXPECT_EQ(dataset.status().code(), StatusCode::kNotFound);
  const std::string& message = dataset.status().message();
  EXPECT_NE(message.find(AnnotationPath(kSeq10, 11212).string()), std::string::npos) << message;
  EXPECT_NE(message.find("frame without an image"), std::string::npos) << message;
}

TEST_F(Modd2DatasetTest, UndecodableImageAndBrokenAnnotationFailOnLoad) {
  AddSequence(kSeq10, 2);
  std::ofstream(ImagePath(kSeq10, 11211), std::ios::trunc) << "not a jpeg";
  ASSERT_TRUE(modd2_test::WriteStructMat(
      AnnotationPath(kSeq10, 11212).string(), "annotations",
      {modd2_test::Matrix("sea_edge", {{1, 2, 3}}), modd2_test::Matrix("obstacles", {}, 4)}));
  Result<std::unique_ptr<Dataset>> dataset =
      OpenModd2Dataset(root_.string(), "train", OneTrainSequence(kSeq10));
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  const Result<Sample> bad_image = (*dataset)->Load(0);
  ASSERT_FALSE(bad_image.ok());
  EXPECT_NE(bad_image.status().message().find(ImagePath(kSeq10, 11211).string()),
            std::string::npos);
  const Result<Sample> bad_mat = (*dataset)->Load(1);
  ASSERT_FALSE(bad_mat.ok());
  EXPECT_NE(bad_mat.status().message().find("annotations.sea_edge"), std::string::npos);
}

TEST_F(Modd2DatasetTest, DefaultSplitNeedsItsSequences) {
  // Only one of the default split's eight train sequences is present.
  const std::string first_train = DefaultModd2Split().train.front();
  AddSequence(first_train, 1);
  const Result<std::unique_ptr<Dataset>> dataset = OpenModd2Dataset(root_.string(), "train");
  ASSERT_FALSE(dataset.ok());
  EXPECT_EQ(dataset.status().code(), StatusCode::kNotFound);
  const std::string& message = dataset.status().message();
  EXPECT_NE(message.find("7 of its 8"), std::string::npos) << message;
  EXPECT_NE(message.find(DefaultModd2Split().train.back()), std::string::npos) << message;
  EXPECT_NE(message.find(kModd2DefaultSplitVersion), std::string::npos) << message;
  EXPECT_NE(message.find("Modd2Options"), std::string::npos) << message;
}

TEST_F(Modd2DatasetTest, DefaultSplitOpensWhenComplete) {
  for (const std::string& seq : DefaultModd2Split().train) AddSequence(seq, 1);
  Result<std::unique_ptr<Dataset>> dataset = OpenModd2Dataset(root_.string(), "train");
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  EXPECT_EQ((*dataset)->size(), 8u);
  ASSERT_EQ(DefaultModd2Split().train[0], "kope67-00-00040950-00041190");
  EXPECT_EQ((*dataset)->name(0), "kope67-00-00040950-00041190_00040951L");
}

TEST_F(Modd2DatasetTest, UnknownSequenceWithDefaultSplit) {
  for (const std::string& seq : DefaultModd2Split().train) AddSequence(seq, 1);
  AddSequence("kope99-00-00000100-00000200", 1);
  Result<std::unique_ptr<Dataset>> dataset = OpenModd2Dataset(root_.string(), "train");
  ASSERT_FALSE(dataset.ok());
  EXPECT_EQ(dataset.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(dataset.status().message().find("kope99-00-00000100-00000200"), std::string::npos)
      << dataset.status().message();
  // With an explicit split, other folders are fine.
  Modd2Options options;
  options.train_sequences = {"kope99-00-00000100-00000200"};
  dataset = OpenModd2Dataset(root_.string(), "train", options);
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  EXPECT_EQ((*dataset)->size(), 1u);
}

TEST_F(Modd2DatasetTest, SplitFileInTheRoot) {
  AddSequence(kSeq10, 1);
  AddSequence(kSeq11, 2);
  std::ofstream(root_ / kModd2SplitFileName) << "train " << kSeq10 << "\ntest " << kSeq11 << "\n";
  Result<std::unique_ptr<Dataset>> train = OpenModd2Dataset(root_.string(), "train");
  ASSERT_TRUE(train.ok()) << train.status().message();
  EXPECT_EQ((*train)->size(), 1u);
  Result<std::unique_ptr<Dataset>> test = OpenModd2Dataset(root_.string(), "test");
  ASSERT_TRUE(test.ok()) << test.status().message();
  EXPECT_EQ((*test)->size(), 2u);
  Result<std::unique_ptr<Dataset>> all = OpenModd2Dataset(root_.string(), "all");
  ASSERT_TRUE(all.ok()) << all.status().message();
  EXPECT_EQ((*all)->size(), 3u);
  EXPECT_FALSE(OpenModd2Dataset(root_.string(), "validation").ok());
  // Options still win over the file.
  Modd2Options options;
  options.test_sequences = {kSeq10};
  test = OpenModd2Dataset(root_.string(), "test", options);
  ASSERT_TRUE(test.ok()) << test.status().message();
  EXPECT_EQ((*test)->size(), 1u);
  // An empty list is an error, not an empty dataset.
  const Result<std::unique_ptr<Dataset>> empty = OpenModd2Dataset(root_.string(), "train", options);
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.status().message().find("lists no sequences"), std::string::npos);
}

TEST_F(Modd2DatasetTest, RectifiedLayout) {
  const long long start = 11210;
  AddFrame(kSeq10, start, false, /*rectified=*/true);
  AddFrame(kSeq10, start + 1, true, /*rectified=*/true);
  Modd2Options options = OneTrainSequence(kSeq10);
  options.rectified = true;
  EXPECT_TRUE(LooksLikeModd2(root_.string()));
  Result<std::unique_ptr<Dataset>> dataset = OpenModd2Dataset(root_.string(), "train", options);
  ASSERT_TRUE(dataset.ok()) << dataset.status().message();
  EXPECT_EQ((*dataset)->size(), 1u);
  // The raw layout is absent.
  options.rectified = false;
  dataset = OpenModd2Dataset(root_.string(), "train", options);
  ASSERT_FALSE(dataset.ok());
  EXPECT_NE(dataset.status().message().find("annotationsV2"), std::string::npos);
}

TEST_F(Modd2DatasetTest, NotAModd2Root) {
  EXPECT_FALSE(LooksLikeModd2(root_.string()));
  EXPECT_FALSE(LooksLikeModd2((root_ / "missing").string()));
  const Result<std::unique_ptr<Dataset>> dataset =
      OpenModd2Dataset((root_ / "missing").string(), "test");
  ASSERT_FALSE(dataset.ok());
  EXPECT_EQ(dataset.status().code(), StatusCode::kNotFound);
  fs::create_directories(root_ / "video_data");
  fs::create_directories(root_ / "annotations_v2_redone");  // the name the zip unpacks to
  EXPECT_TRUE(LooksLikeModd2(root_.string()));
}

}  // namespace
}  // namespace tod
