#include "core/edges/edge_source.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace tod {
namespace {

std::string TempPath(const std::string& name) {
  return (std::filesystem::path(testing::TempDir()) / name).string();
}

TEST(GradientEdgeSource, StepEdgeMatchesHandComputedProfile) {
  // Black for x < 32, white from x = 32. Triangle radius 1 gives L = 0.25 at x = 31 and 0.75 at
  // x = 32; central differences give 0.125, 0.375, 0.375, 0.125 at x = 30..33 and 0 elsewhere.
  // 4 of 64 columns are non-zero, so the 99th percentile is 0.375.
  cv::Mat3b image(64, 64, cv::Vec3b(0, 0, 0));
  image(cv::Rect(32, 0, 32, 64)).setTo(cv::Vec3b(255, 255, 255));
  const auto source = CreateGradientEdgeSource();
  EXPECT_EQ(source->kind(), EdgeKind::kGradient);
  const cv::Mat1f edge = source->Compute(image);
  ASSERT_EQ(edge.size(), image.size());
  for (const int y : {0, 20, 63}) {
    EXPECT_NEAR(edge(y, 31), 1.f, 1e-3);
    EXPECT_NEAR(edge(y, 32), 1.f, 1e-3);
    EXPECT_NEAR(edge(y, 30), 1.f / 3.f, 1e-3);
    EXPECT_NEAR(edge(y, 33), 1.f / 3.f, 1e-3);
    EXPECT_NEAR(edge(y, 10), 0.f, 1e-4);
    EXPECT_NEAR(edge(y, 50), 0.f, 1e-4);
  }
  double min_value = 0.0;
  double max_value = 0.0;
  cv::minMaxLoc(edge, &min_value, &max_value);
  EXPECT_GE(min_value, 0.0);
  EXPECT_LE(max_value, 1.0);
}

TEST(GradientEdgeSource, FlatImageIsAllZero) {
  const cv::Mat1f edge =
      CreateGradientEdgeSource()->Compute(cv::Mat3b(20, 30, cv::Vec3b(10, 200, 90)));
  ASSERT_EQ(edge.size(), cv::Size(30, 20));
  EXPECT_EQ(cv::countNonZero(edge), 0);
}

TEST(GradientEdgeSource, SparseEdgesFallBackToTheMaximum) {
  // One bright pixel in 100 x 100: under 1 % of pixels respond, the 99th percentile is 0, and the
  // map is normalised by its maximum instead.
  cv::Mat3b image(100, 100, cv::Vec3b(0, 0, 0));
  image(50, 50) = cv::Vec3b(255, 255, 255);
  const cv::Mat1f edge = CreateGradientEdgeSource()->Compute(image);
  double max_value = 0.0;
  cv::minMaxLoc(edge, nullptr, &max_value);
  EXPECT_FLOAT_EQ(static_cast<float>(max_value), 1.f);
  EXPECT_EQ(edge(10, 10), 0.f);
}

TEST(GradientEdgeSource, LargerRadiusSpreadsTheResponse) {
  cv::Mat3b image(40, 40, cv::Vec3b(0, 0, 0));
  image(cv::Rect(20, 0, 20, 40)).setTo(cv::Vec3b(255, 255, 255));
  const cv::Mat1f narrow = CreateGradientEdgeSource({.smooth_radius = 1})->Compute(image);
  const cv::Mat1f wide = CreateGradientEdgeSource({.smooth_radius = 4})->Compute(image);
  EXPECT_EQ(narrow(5, 15), 0.f);
  EXPECT_GT(wide(5, 15), 0.f);
}

TEST(GradientEdgeSource, EmptyImageGivesEmptyMap) {
  EXPECT_TRUE(CreateGradientEdgeSource()->Compute(cv::Mat3b()).empty());
}

TEST(SedEdgeSource, MissingFileIsNotFoundNamingThePath) {
  const std::string path = TempPath("no_such_sed_model.yml.gz");
  const auto source = CreateSedEdgeSource(path);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kNotFound);
  EXPECT_NE(source.status().message().find(path), std::string::npos);
}

TEST(SedEdgeSource, GarbageFileIsAnErrorNamingThePath) {
  const std::string path = TempPath("garbage_sed_model.yml");
  {
    std::ofstream out(path, std::ios::binary);
    for (int i = 0; i < 300; ++i) out.put(static_cast<char>((i * 37 + 11) % 256));
  }
  const auto source = CreateSedEdgeSource(path);
  ASSERT_FALSE(source.ok());
  EXPECT_NE(source.status().message().find(path), std::string::npos);
  std::filesystem::remove(path);
}

TEST(SedEdgeSource, YamlWithoutModelFieldsIsAnError) {
  const std::string path = TempPath("not_a_sed_model.yml");
  {
    std::ofstream out(path);
    out << "%YAML:1.0\n---\nanswer: 42\n";
  }
  const auto source = CreateSedEdgeSource(path);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(source.status().message().find(path), std::string::npos);
  EXPECT_NE(source.status().message().find("options"), std::string::npos);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace tod
