#include "core/evaluation/stage_images.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/pipeline/obstacle_detector.h"
#include "tests/pipeline/tiny_bundle.h"

namespace tod {
namespace {
namespace fs = std::filesystem;

std::vector<std::string> Names(const StageImages& stages) {
  std::vector<std::string> names;
  for (const StageImage& image : stages.images) names.push_back(image.name);
  return names;
}

const cv::Mat& Picture(const StageImages& stages, const std::string& name) {
  for (const StageImage& image : stages.images)
    if (image.name == name) return image.pixels;
  static const cv::Mat kNone;
  return kNone;
}

// The pictures as `tod detect --stages` makes them: from the detection's own trace.
Result<StageImages> Render(const ModelBundle& bundle, const cv::Mat3b& frame,
                           const StageImageOptions& options = {}) {
  const ObstacleDetector detector(bundle, "tiny");
  FrameTrace trace;
  const Result<Detection> detection = detector.Detect(frame, DetectOptions{}, &trace);
  if (!detection.ok()) return detection.status();
  return RenderStageImages(trace, frame, options);
}

class StageImagesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    bundle_ = new ModelBundle(TinyBundle());
    frame_ = new cv::Mat3b(RoadFrame(512, 256));
    auto stages = Render(*bundle_, *frame_);
    ASSERT_TRUE(stages.ok()) << stages.status().ToString();
    stages_ = new StageImages(std::move(*stages));
  }
  static void TearDownTestSuite() {
    delete stages_;
    delete frame_;
    delete bundle_;
  }
  static ModelBundle* bundle_;
  static cv::Mat3b* frame_;
  static StageImages* stages_;
};
ModelBundle* StageImagesTest::bundle_ = nullptr;
cv::Mat3b* StageImagesTest::frame_ = nullptr;
StageImages* StageImagesTest::stages_ = nullptr;

TEST_F(StageImagesTest, EveryStageIsAFrameSizedPictureInPipelineOrder) {
  const std::vector<std::string> expected = {"base_edges",   "enhanced_edges", "superpixels",
                                             "occlusion",    "regions",        "proposals_R1",
                                             "proposals_R2", "proposals_R3",   "proposals_R4"};
  EXPECT_EQ(Names(*stages_), expected);
  for (const StageImage& image : stages_->images) {
    EXPECT_EQ(image.pixels.size(), frame_->size()) << image.name;
    const bool grey = image.name == "base_edges" || image.name == "enhanced_edges";
    EXPECT_EQ(image.pixels.type(), grey ? CV_8UC1 : CV_8UC3) << image.name;
  }
}

TEST_F(StageImagesTest, EdgeMapsLieOnR1AndTheEnhancedOneIsScaledToK) {
  const FrameGeometry geometry = GeometryForFrame(*bundle_, frame_->cols, frame_->rows);
  const cv::Rect r1 = ClipToImage(geometry.regions.layers[0], frame_->cols, frame_->rows).rect();
  const cv::Mat1b base = Picture(*stages_, "base_edges");
  const cv::Mat1b enhanced = Picture(*stages_, "enhanced_edges");
  const int layers = geometry.regions.num_layers();
  int strong = 0;
  for (int y = 0; y < base.rows; ++y)
    for (int x = 0; x < base.cols; ++x) {
      if (!r1.contains({x, y})) {
        ASSERT_EQ(base(y, x), 0) << x << "," << y;
        ASSERT_EQ(enhanced(y, x), 0) << x << "," << y;
        continue;
      }
      strong += base(y, x) > 25;
      // 255 = 1.0 for E, 255 = K for Ê = n(p) E(p): both rounded once.
      const double expected = geometry.regions.LayerCount(x, y) * base(y, x) / double(layers);
      ASSERT_NEAR(enhanced(y, x), expected, 1.0) << x << "," << y;
    }
  EXPECT_GT(strong, 100);  // the blocks' outlines
}

TEST_F(StageImagesTest, SuperpixelBoundariesAreDrawnOnlyInsideR1) {
  const nlohmann::json& box = stages_->counts["r1"];
  const cv::Rect r1(box["x"].get<int>(), box["y"].get<int>(), box["w"].get<int>(),
                    box["h"].get<int>());
  const cv::Mat3b picture = Picture(*stages_, "superpixels");
  int inside = 0, outside = 0;
  for (int y = 0; y < picture.rows; ++y)
    for (int x = 0; x < picture.cols; ++x)
      if (picture(y, x) == cv::Vec3b(0, 255, 255)) (r1.contains({x, y}) ? inside : outside)++;
  EXPECT_GT(inside, 1000);
  EXPECT_EQ(outside, 0);
  // The frame is dimmed, so a drawn boundary stands out everywhere.
  EXPECT_LE(picture(0, 0)[2], (*frame_)(0, 0)[2] / 2 + 1);
}

TEST_F(StageImagesTest, CountsDescribeEveryStageAndAddUpToTheDetectorsProposals) {
  const nlohmann::json& c = stages_->counts;
  EXPECT_EQ(c["width"], 512);
  EXPECT_EQ(c["height"], 256);
  EXPECT_EQ(c["layers"], 4);
  EXPECT_GT(c["base_edge_pixels"].get<long long>(), 0);
  // n(p) >= 1 on R1, so enhancement only adds edge pixels.
  EXPECT_GE(c["enhanced_edge_pixels"].get<long long>(), c["base_edge_pixels"].get<long long>());
  EXPECT_GT(c["superpixels"].get<int>(), 10);
  EXPECT_GT(c["occlusion_edge_pixels"].get<long long>(), 0);
  ASSERT_EQ(c["regions"].size(), 4u);
  long long total = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    const nlohmann::json& r = c["regions"][k];
    EXPECT_EQ(r["name"], "R" + std::to_string(k + 1));
    EXPECT_GT(r["w"].get<int>(), 0);
    EXPECT_LE(r["edge_groups"].get<long long>(), r["edge_pixels"].get<long long>());
    EXPECT_GE(r["windows_scored"].get<long long>(), r["windows_nonzero"].get<long long>());
    EXPECT_GE(r["boxes_after_nms"].get<long long>(), r["proposals_kept"].get<long long>());
    EXPECT_EQ(r["proposals_drawn"].get<long long>(),
              std::min(200LL, r["proposals_kept"].get<long long>()));
    total += r["proposals_kept"].get<long long>();
  }
  EXPECT_GT(c["regions"][0]["edge_groups"].get<long long>(), 0);
  EXPECT_GT(total, 0);
  // The cross-region merge removes inner regions' copies of boxes: never more than the sum.
  EXPECT_LE(c["proposals_total"].get<long long>(), total);
  EXPECT_GT(c["proposals_total"].get<long long>(), 0);
  // The same stages as the detector: it regresses exactly these proposals.
  const ObstacleDetector detector(*bundle_, "tiny");
  DetectOptions options;
  options.max_proposals = 1 << 30;
  auto detection = detector.Detect(*frame_, options);
  ASSERT_TRUE(detection.ok());
  EXPECT_EQ(static_cast<long long>(detection->proposals.size()),
            c["proposals_total"].get<long long>());
}

TEST_F(StageImagesTest, ProposalPicturesDrawAtMostTheRequestedNumber) {
  StageImageOptions options;
  options.proposals_drawn = 3;
  auto stages = Render(*bundle_, *frame_, options);
  ASSERT_TRUE(stages.ok());
  for (const nlohmann::json& r : stages->counts["regions"])
    EXPECT_EQ(r["proposals_drawn"].get<long long>(),
              std::min(3LL, r["proposals_kept"].get<long long>()));
}

TEST(StageImagesFrameTest, AnyFrameSizeGivesPicturesOfThatSizeAndTinyFramesAreRefused) {
  const ModelBundle bundle = TinyBundle();
  const cv::Mat3b frame = RoadFrame(301, 157);
  auto stages = Render(bundle, frame);
  ASSERT_TRUE(stages.ok()) << stages.status().ToString();
  for (const StageImage& image : stages->images)
    EXPECT_EQ(image.pixels.size(), frame.size()) << image.name;
  auto tiny = Render(bundle, cv::Mat3b(10, 10, cv::Vec3b(0, 0, 0)));
  ASSERT_FALSE(tiny.ok());
  EXPECT_NE(tiny.status().message().find("10x10"), std::string::npos);
}

TEST(StageImagesWriteTest, WritesEveryPictureAndTheCounts) {
  const fs::path dir =
      fs::temp_directory_path() / ("tod_stage_images_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  StageImages stages;
  stages.images.push_back({"base_edges", cv::Mat1b(20, 30, uchar{7})});
  stages.images.push_back({"regions", cv::Mat3b(20, 30, cv::Vec3b(1, 2, 3))});
  stages.counts = {{"superpixels", 12}};
  ASSERT_TRUE(WriteStageImages(stages, (dir / "frame").string()).ok());
  const cv::Mat grey =
      cv::imread((dir / "frame_stage_base_edges.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(grey.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(grey != 7), 0);
  const cv::Mat colour = cv::imread((dir / "frame_stage_regions.png").string());
  EXPECT_EQ(colour.size(), cv::Size(30, 20));
  std::ifstream in(dir / "frame_stages.json");
  EXPECT_EQ(nlohmann::json::parse(in)["superpixels"], 12);
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 3);  // no temporary files left behind
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tod
