// Regression tests for inputs found by fuzz_modd2_mat (README, "Fuzzing"): MAT files whose arrays
// claim far more elements than they hold, which libmatio would allocate before failing.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/modd2/mat5_bounds.h"
#include "core/modd2/modd2_reader.h"
#include "tests/modd2/mat_fixture.h"
#include "tests/test_env.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void PutU32(std::string* bytes, size_t at, uint32_t value) {
  for (int i = 0; i < 4; ++i) (*bytes)[at + i] = static_cast<char>((value >> (8 * i)) & 0xFF);
}

// A 378-byte compressed annotation (a mutated seed) whose variable inflates to far less than its
// headers claim: libmatio created 9 million struct fields for it, over 2 GB (the fuzzer's
// out-of-memory limit), before this check existed.
TEST(Mat5BoundsTest, FuzzerInputClaimingMillionsOfStructFieldsIsRefusedQuickly) {
  const fs::path input = fs::path(testing_env::SourceDir()) /
                         "tests/fuzz/corpus/fuzz_modd2_mat/"
                         "oom-d56342ba33a6f5a014e325e68c304e71d1ab2b89";
  ASSERT_TRUE(fs::exists(input)) << input;
  const auto start = std::chrono::steady_clock::now();
  const Result<Modd2Annotation> annotation = ReadModd2Annotation(input.string());
  ASSERT_FALSE(annotation.ok());
  EXPECT_EQ(annotation.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(annotation.status().message().find("not a valid MAT file"), std::string::npos)
      << annotation.status().message();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

class Mat5BoundsFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (fs::path(::testing::TempDir()) / "mat5_bounds.mat").string();
    ASSERT_TRUE(modd2_test::WriteAnnotation(path_, {{1, 20}, {64, 22}}, {{10, 30, 8, 6}},
                                            MAT_COMPRESSION_NONE));
    bytes_ = ReadAll(path_);
  }
  void TearDown() override { fs::remove(path_); }

  // Byte offset of the first dimensions subelement after `from` (tag miINT32, 8 bytes).
  size_t DimsAfter(size_t from) const {
    const std::string tag("\x05\0\0\0\x08\0\0\0", 8);
    const size_t at = bytes_.find(tag, from);
    EXPECT_NE(at, std::string::npos);
    return at + 8;
  }

  std::string path_;
  std::string bytes_;
};

TEST_F(Mat5BoundsFileTest, ValidAnnotationPasses) {
  EXPECT_TRUE(CheckMat5Bounds(bytes_, path_).ok());
  EXPECT_TRUE(ReadModd2Annotation(path_).ok());
}

TEST_F(Mat5BoundsFileTest, StructClaimingAHugeSizeIsRefused) {
  std::string broken = bytes_;
  PutU32(&broken, DimsAfter(128), 100'000'000);  // 'annotations' as 100000000 x 1
  const Status status = CheckMat5Bounds(broken, "x.mat");
  EXPECT_EQ(status.code(), StatusCode::kDataLoss) << status.message();
}

TEST_F(Mat5BoundsFileTest, NumericFieldClaimingAHugeSizeIsRefused) {
  std::string broken = bytes_;
  const size_t struct_dims = DimsAfter(128);
  PutU32(&broken, DimsAfter(struct_dims), 50'000'000);  // sea_edge as 50000000 x 2
  const Status status = CheckMat5Bounds(broken, "x.mat");
  EXPECT_EQ(status.code(), StatusCode::kDataLoss) << status.message();
}

TEST(Mat5BoundsTest, NotLevel5IsLeftToMatio) {
  EXPECT_TRUE(CheckMat5Bounds("", "x.mat").ok());
  EXPECT_TRUE(CheckMat5Bounds(std::string(200, 'x'), "x.mat").ok());
}

}  // namespace
}  // namespace tod
