// ReadModd2Annotation against MAT fixtures written with libmatio (compressed or not, double or
// single, empty arrays of both shapes, extra fields) and against broken files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/modd2/modd2_reader.h"
#include "tests/modd2/mat_fixture.h"

namespace tod {
namespace {

namespace fs = std::filesystem;
using modd2_test::Matrix;
using modd2_test::WriteAnnotation;
using modd2_test::WriteNumericMat;
using modd2_test::WriteStructMat;

const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

class Modd2AnnotationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) /
           ("modd2_annotation_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

const std::vector<std::vector<double>> kSeaEdge = {
    {-3, 4.25}, {kNan, 7}, {10, 4.5}, {1300.5, 3.75}, {kInf, 2}};
const std::vector<std::vector<double>> kObstacles = {{2.5, 6.25, 5.5, 5.5}, {1270.75, 950, 30, 12}};

void ExpectFixtureValues(const Modd2Annotation& a) {
  ASSERT_EQ(a.sea_edge.size(), 5u);
  EXPECT_EQ(a.sea_edge[0], cv::Point2d(-3, 4.25));
  EXPECT_TRUE(std::isnan(a.sea_edge[1].x));
  EXPECT_EQ(a.sea_edge[1].y, 7);
  EXPECT_EQ(a.sea_edge[3], cv::Point2d(1300.5, 3.75));
  EXPECT_TRUE(std::isinf(a.sea_edge[4].x));
  ASSERT_EQ(a.obstacles.size(), 2u);
  EXPECT_EQ(a.obstacles[0], cv::Rect2d(2.5, 6.25, 5.5, 5.5));
  EXPECT_EQ(a.obstacles[1], cv::Rect2d(1270.75, 950, 30, 12));
}

TEST_F(Modd2AnnotationTest, ReadsEveryCompressionAndClass) {
  // All fixture values are exact in single precision, so both classes read back identically.
  for (const matio_compression compression : {MAT_COMPRESSION_ZLIB, MAT_COMPRESSION_NONE}) {
    for (const bool single : {false, true}) {
      SCOPED_TRACE(std::string(compression == MAT_COMPRESSION_ZLIB ? "zlib" : "none") +
                   (single ? " single" : " double"));
      const std::string path = Path("frame.mat");
      ASSERT_TRUE(WriteAnnotation(path, kSeaEdge, kObstacles, compression, single));
      const Result<Modd2Annotation> a = ReadModd2Annotation(path);
      ASSERT_TRUE(a.ok()) << a.status().message();
      ExpectFixtureValues(*a);
    }
  }
}

TEST_F(Modd2AnnotationTest, EmptyObstacleArraysOfBothShapes) {
  for (const std::size_t cols : {std::size_t{0}, std::size_t{4}}) {
    SCOPED_TRACE("0x" + std::to_string(cols));
    const std::string path = Path("empty.mat");
    ASSERT_TRUE(WriteStructMat(path, "annotations",
                               {Matrix("sea_edge", kSeaEdge), Matrix("obstacles", {}, cols)}));
    const Result<Modd2Annotation> a = ReadModd2Annotation(path);
    ASSERT_TRUE(a.ok()) << a.status().message();
    EXPECT_TRUE(a->obstacles.empty());
    EXPECT_EQ(a->sea_edge.size(), 5u);
  }
}

TEST_F(Modd2AnnotationTest, IgnoresUnknownFieldsAndFieldOrder) {
  const std::string path = Path("extra.mat");
  ASSERT_TRUE(WriteStructMat(path, "annotations",
                             {Matrix("obstacles", kObstacles), Matrix("comment", {{1, 2, 3}}),
                              Matrix("sea_edge", kSeaEdge, 2, /*single=*/true)}));
  const Result<Modd2Annotation> a = ReadModd2Annotation(path);
  ASSERT_TRUE(a.ok()) << a.status().message();
  ExpectFixtureValues(*a);
}

TEST_F(Modd2AnnotationTest, EmptySeaEdgeIsNoPoints) {
  const std::string path = Path("no_edge.mat");
  ASSERT_TRUE(WriteAnnotation(path, {}, kObstacles));
  const Result<Modd2Annotation> a = ReadModd2Annotation(path);
  ASSERT_TRUE(a.ok()) << a.status().message();
  EXPECT_TRUE(a->sea_edge.empty());
  EXPECT_EQ(a->obstacles.size(), 2u);
}

// The error's message must name the file and, where there is one, the field.
void ExpectError(const Result<Modd2Annotation>& r, StatusCode code, const std::string& path,
                 const std::string& field) {
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), code) << r.status().message();
  EXPECT_NE(r.status().message().find(path), std::string::npos) << r.status().message();
  EXPECT_NE(r.status().message().find(field), std::string::npos) << r.status().message();
}

TEST_F(Modd2AnnotationTest, MissingAnnotationsVariable) {
  const std::string path = Path("other.mat");
  ASSERT_TRUE(WriteStructMat(path, "labels",
                             {Matrix("sea_edge", kSeaEdge), Matrix("obstacles", kObstacles)}));
  ExpectError(ReadModd2Annotation(path), StatusCode::kNotFound, path, "'annotations'");
}

TEST_F(Modd2AnnotationTest, AnnotationsNotAStruct) {
  const std::string path = Path("numeric.mat");
  ASSERT_TRUE(WriteNumericMat(path, Matrix("annotations", {{1, 2}})));
  ExpectError(ReadModd2Annotation(path), StatusCode::kInvalidArgument, path, "struct");
}

TEST_F(Modd2AnnotationTest, AnnotationsStructArray) {
  const std::string path = Path("array.mat");
  ASSERT_TRUE(WriteStructMat(path, "annotations",
                             {Matrix("sea_edge", kSeaEdge), Matrix("obstacles", kObstacles)},
                             MAT_COMPRESSION_ZLIB, /*elements=*/2));
  ExpectError(ReadModd2Annotation(path), StatusCode::kInvalidArgument, path, "1x1");
}

TEST_F(Modd2AnnotationTest, MissingFields) {
  const std::string path = Path("fields.mat");
  ASSERT_TRUE(WriteStructMat(path, "annotations", {Matrix("obstacles", kObstacles)}));
  ExpectError(ReadModd2Annotation(path), StatusCode::kNotFound, path, "annotations.sea_edge");
  ASSERT_TRUE(WriteStructMat(path, "annotations", {Matrix("sea_edge", kSeaEdge)}));
  ExpectError(ReadModd2Annotation(path), StatusCode::kNotFound, path, "annotations.obstacles");
}

TEST_F(Modd2AnnotationTest, SeaEdgeWithThreeColumns) {
  const std::string path = Path("three.mat");
  ASSERT_TRUE(WriteStructMat(
      path, "annotations",
      {Matrix("sea_edge", {{1, 2, 3}, {4, 5, 6}}), Matrix("obstacles", kObstacles)}));
  const Result<Modd2Annotation> r = ReadModd2Annotation(path);
  ExpectError(r, StatusCode::kInvalidArgument, path, "annotations.sea_edge");
  EXPECT_NE(r.status().message().find("2x3"), std::string::npos) << r.status().message();
}

TEST_F(Modd2AnnotationTest, ObstaclesWithWrongShapeOrNonFiniteValue) {
  const std::string path = Path("boxes.mat");
  ASSERT_TRUE(WriteStructMat(path, "annotations",
                             {Matrix("sea_edge", kSeaEdge), Matrix("obstacles", {{1, 2, 3}})}));
  ExpectError(ReadModd2Annotation(path), StatusCode::kInvalidArgument, path,
              "annotations.obstacles");
  ASSERT_TRUE(WriteAnnotation(path, kSeaEdge, {{1, 2, 3, 4}, {5, kNan, 7, 8}}));
  ExpectError(ReadModd2Annotation(path), StatusCode::kInvalidArgument, path, "row 2");
}

TEST_F(Modd2AnnotationTest, MissingOrCorruptFile) {
  const std::string missing = Path("missing.mat");
  ExpectError(ReadModd2Annotation(missing), StatusCode::kNotFound, missing, "not found");
  const std::string garbage = Path("garbage.mat");
  std::ofstream(garbage) << "this is not a MAT file at all";
  ExpectError(ReadModd2Annotation(garbage), StatusCode::kDataLoss, garbage, "MAT");
  // A valid file cut in half.
  const std::string cut = Path("cut.mat");
  ASSERT_TRUE(WriteAnnotation(cut, kSeaEdge, kObstacles, MAT_COMPRESSION_NONE));
  fs::resize_file(cut, fs::file_size(cut) / 2);
  const Result<Modd2Annotation> r = ReadModd2Annotation(cut);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find(cut), std::string::npos) << r.status().message();
}

}  // namespace
}  // namespace tod
