// Regression tests for inputs found by fuzz_modd2_mat (docs/service.md#found-and-fixed): MAT files
// whose arrays claim far more elements than they hold, and files without a Level-5 header, whose
// MAT v4 header libmatio trusts; libmatio would allocate what they claim before failing.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/modd2/mat5_bounds.h"
#include "core/modd2/modd2_reader.h"
#include "tests/data/temp_dir.h"
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

// Reads `path` as an annotation and expects a quick DataLoss naming the invalid MAT file.
void ExpectRefusedQuickly(const fs::path& path) {
  ASSERT_TRUE(fs::exists(path)) << path;
  const auto start = std::chrono::steady_clock::now();
  const Result<Modd2Annotation> annotation = ReadModd2Annotation(path.string());
  ASSERT_FALSE(annotation.ok());
  EXPECT_EQ(annotation.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(annotation.status().message().find("not a valid MAT file"), std::string::npos)
      << annotation.status().message();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

fs::path CorpusInput(const std::string& name) {
  return fs::path(testing_env::SourceDir()) / "tests/fuzz/corpus/fuzz_modd2_mat" / name;
}

// A 378-byte compressed annotation (a mutated seed) whose variable inflates to far less than its
// headers claim: libmatio created 9 million struct fields for it, over 2 GB (the fuzzer's
// out-of-memory limit), before this check existed.
TEST(Mat5BoundsTest, FuzzerInputClaimingMillionsOfStructFieldsIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("oom-d56342ba33a6f5a014e325e68c304e71d1ab2b89"));
}

// A 147-byte mutated seed whose endian indicator is gone: libmatio read it as MAT v4, took bytes
// 16-19 of the header text as a 1.1 GB variable name and allocated and cleared that much in
// Mat_Open (over 25 s under the fuzzer's sanitizers, 4 s without).
TEST(Mat5BoundsTest, FuzzerInputReadAsMatV4WithAHugeNameIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("timeout-e44665c1cd7483b522a68308cd294bc7837c40ea"));
}

// A 424-byte mutated seed: 'annotations' has an unknown array class (33), which the walker used to
// skip, and a dimensions tag claiming 4 GB; libmatio allocated 8 bytes per claimed dimension, 8 GB
// (over 10 s in the sanitizers' allocator) before failing.
TEST(Mat5BoundsTest, FuzzerInputWithUnknownClassAndHugeDimensionsIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("timeout-3885b1deca9263bffaec7ca79eb5077e80ec188c"));
}

// A 392-byte mutated seed: a function handle array (class 16) of 1 x 1.9 billion. libmatio reads
// function handles as cell arrays and allocated a pointer per claimed element (15 GB; out of
// memory under the fuzzer); the walker used to stop at classes past the numeric ones.
TEST(Mat5BoundsTest, FuzzerInputWithAHugeFunctionHandleArrayIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("oom-4470bbbeaea222285e23e1cc994a3d7d31b5bd4c"));
}

// A 392-byte mutated seed found by CI's 5 s fuzz_smoke: the first variable is an opaque object
// (class 17) whose third element's tag claims 2 GB; libmatio allocated that much for it (out of
// memory under the fuzzer), and the walk used to stop at an opaque object's dimensions.
TEST(Mat5BoundsTest, FuzzerInputWithAnOpaqueObjectClaimingAHugeNameIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("oom-2c3f1075e806a48cb08552a31be9c000ddd3ce32"));
}

// A 392-byte mutated seed found by CI's 5 s fuzz_smoke: the 'annotations' variable's tag claims 0
// bytes, and libmatio read the struct header that follows anyway (1 x 687 million elements, two
// fields) and allocated for it (out of memory under the fuzzer); the walk took those bytes for
// further elements.
TEST(Mat5BoundsTest, FuzzerInputWithAZeroByteVariableIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("oom-851a22babb87dacc1e4f91f49d8edd8f74101167"));
}

// A 425-byte mutated seed found by CI's 5 s fuzz_smoke: a 4 x 2 single array (a field of the
// 'annotations' struct) whose data element's tag claims 2 GB in an 80-byte array; libmatio asked
// calloc for 2^64 - 16 M bytes (AddressSanitizer: allocation-size-too-big), and the walk checked
// a numeric array's dimensions but not its data tags.
TEST(Mat5BoundsTest, FuzzerInputWithANumericDataTagClaimingAHugeSizeIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("crash-719ed68f46305663cb0bf9ae26e4260002656a5e"));
}

// A 425-byte mutated seed found by a 120 s run of fuzz_modd2_mat after the fix above: the struct's
// array flags tag claims 110 bytes, so the walk took the dimensions, name and field names for
// flags and read the rest out of step, while libmatio reads 8 bytes of flags whatever the tag says
// and then a field's dimensions of 3 x -268 M, for which it allocated 48 GB.
TEST(Mat5BoundsTest, FuzzerInputWithOversizedArrayFlagsIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("crash-21f975afa41a49ca7730a43deb45953b585520f0"));
}

// A 424-byte mutated seed found by CI's 5 s fuzz_smoke on an unchanged main: the struct's field
// name length is a regular 8-byte element instead of a small one. libmatio reads 8 bytes for the
// length whatever their tag, so it took the element's value (1, then 0xf6000001) as the names'
// tag, 4 GB of names of 8 bytes, and asked malloc for 4.1 GB of pointers; the walk read the
// length's tag as a whole element and the names from the bytes after it.
TEST(Mat5BoundsTest, FuzzerInputWithARegularFieldNameLengthElementIsRefusedQuickly) {
  ExpectRefusedQuickly(CorpusInput("oom-772e0b93"));
}

// The same cause, constructed: a MAT v4 header (type, rows, columns, complex flag, name length)
// claiming a 2 GB name, followed by a few bytes.
TEST(Mat5BoundsTest, MatV4HeaderClaimingAHugeNameIsRefused) {
  std::string bytes(40, 'x');
  for (size_t at = 0; at < 16; ++at) bytes[at] = 0;
  PutU32(&bytes, 4, 1);            // 1 row
  PutU32(&bytes, 8, 1);            // 1 column
  PutU32(&bytes, 16, 0x7FFFFFF0);  // name length
  const fs::path path = fs::path(::testing::TempDir()) / "mat_v4_huge_name.mat";
  std::ofstream(path, std::ios::binary) << bytes;
  ExpectRefusedQuickly(path);
  fs::remove(path);
}

// Each test writes its own file: ctest runs the tests of this fixture in parallel processes, and a
// shared name let one test's TearDown remove the file another was reading.
class Mat5BoundsFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (scratch_.path() / "mat5_bounds.mat").string();
    ASSERT_TRUE(modd2_test::WriteAnnotation(path_, {{1, 20}, {64, 22}}, {{10, 30, 8, 6}},
                                            MAT_COMPRESSION_NONE));
    bytes_ = ReadAll(path_);
  }
  // Byte offset of the first dimensions subelement after `from` (tag miINT32, 8 bytes).
  size_t DimsAfter(size_t from) const {
    const std::string tag("\x05\0\0\0\x08\0\0\0", 8);
    const size_t at = bytes_.find(tag, from);
    EXPECT_NE(at, std::string::npos);
    return at + 8;
  }

  tod::testing::TempDir scratch_;
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

// libmatio reads the dimensions tag of an array of any class, opaque objects included: its size is
// checked for each of them, and classes libmatio does not know are refused.
TEST_F(Mat5BoundsFileTest, DimensionsClaimingMoreThanTheFileAreRefusedForEveryClass) {
  constexpr size_t kClassAt = 128 + 16;     // first value of the first array's flags
  constexpr size_t kDimsSizeAt = 128 + 28;  // byte count in the first array's dimensions tag
  ASSERT_EQ(bytes_.substr(128 + 24, 4), std::string("\x05\0\0\0", 4));
  for (const uint8_t array_class : {1, 2, 6, 15, 16, 17}) {
    std::string broken = bytes_;
    broken[kClassAt] = static_cast<char>(array_class);
    PutU32(&broken, kDimsSizeAt, 0xFFFD0008);
    EXPECT_EQ(CheckMat5Bounds(broken, "x.mat").code(), StatusCode::kDataLoss)
        << "class " << int{array_class};
  }
  for (const uint8_t array_class : {0, 18, 33, 255}) {
    std::string broken = bytes_;
    broken[kClassAt] = static_cast<char>(array_class);
    const Status status = CheckMat5Bounds(broken, "x.mat");
    EXPECT_EQ(status.code(), StatusCode::kDataLoss) << "class " << int{array_class};
    EXPECT_NE(status.message().find("class"), std::string::npos) << status.message();
  }
}

TEST_F(Mat5BoundsFileTest, FunctionHandleArrayClaimingAHugeSizeIsRefused) {
  std::string broken = bytes_;
  broken[128 + 16] = 16;                         // 'annotations' as a function handle array
  PutU32(&broken, DimsAfter(128), 100'000'000);  // of 100000000 x 1
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

// A struct whose element count saturates (2^20 x 2^20) and whose field names are 16 Mi one-byte
// names: the product of the two is 2^64, which must not wrap around to zero.
TEST(Mat5BoundsTest, StructWhoseElementsTimesFieldsOverflowsIsRefused) {
  constexpr uint32_t kFields = 1u << 24;
  std::string matrix;
  const auto element = [&matrix](uint32_t type, const std::string& payload) {
    std::string tag(8, '\0');
    PutU32(&tag, 0, type);
    PutU32(&tag, 4, static_cast<uint32_t>(payload.size()));
    matrix += tag + payload + std::string((8 - payload.size() % 8) % 8, '\0');
  };
  std::string flags(8, '\0'), dims(8, '\0'), name_length(4, '\0');
  PutU32(&flags, 0, 2);  // mxSTRUCT_CLASS
  PutU32(&dims, 0, 1u << 20);
  PutU32(&dims, 4, 1u << 20);
  PutU32(&name_length, 0, 1);
  element(6, flags);  // miUINT32
  element(5, dims);   // miINT32
  element(1, "s");    // miINT8
  // The field name length as MAT files hold it: a small int32 element (4 bytes in the tag).
  std::string small(4, '\0');
  PutU32(&small, 0, (4u << 16) | 5u);
  matrix += small + name_length;
  element(1, std::string(kFields, 'f'));
  std::string bytes(128, ' ');
  PutU32(&bytes, 124, 0x4D490100);  // version 0x0100, "IM"
  std::string tag(8, '\0');
  PutU32(&tag, 0, 14);  // miMATRIX
  PutU32(&tag, 4, static_cast<uint32_t>(matrix.size()));
  bytes += tag + matrix;
  const Status status = CheckMat5Bounds(bytes, "x.mat");
  EXPECT_EQ(status.code(), StatusCode::kDataLoss) << status.message();
}

// Only Level-5 files (and v7.3 ones, HDF5 behind a Level-5 style header) reach libmatio: anything
// else it would read as MAT v4.
TEST(Mat5BoundsTest, FilesWithoutALevel5HeaderAreRefused) {
  EXPECT_EQ(CheckMat5Bounds("", "x.mat").code(), StatusCode::kDataLoss);
  EXPECT_EQ(CheckMat5Bounds(std::string(200, 'x'), "x.mat").code(), StatusCode::kDataLoss);
  std::string header(128, ' ');
  PutU32(&header, 124, 0x4D490300);  // "IM", version 0x0300
  const Status status = CheckMat5Bounds(header, "x.mat");
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find("x.mat"), std::string::npos) << status.message();
  PutU32(&header, 124, 0x4D490200);  // "IM", version 0x0200 (v7.3)
  EXPECT_TRUE(CheckMat5Bounds(header, "x.mat").ok());
  PutU32(&header, 124, 0x4D490100);  // "IM", version 0x0100, no variables
  EXPECT_TRUE(CheckMat5Bounds(header, "x.mat").ok());
}

// A genuine MAT v4 file (written by libmatio) cannot hold the annotations struct: refused before
// libmatio opens it, with the reason.
TEST(Mat5BoundsTest, MatV4FileIsRefused) {
  const std::string path = (fs::path(::testing::TempDir()) / "mat_v4.mat").string();
  ASSERT_TRUE(modd2_test::WriteNumericMat(path, modd2_test::Matrix("annotations", {{1, 2}}),
                                          MAT_COMPRESSION_NONE, MAT_FT_MAT4));
  const Result<Modd2Annotation> annotation = ReadModd2Annotation(path);
  ASSERT_FALSE(annotation.ok());
  EXPECT_EQ(annotation.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(annotation.status().message().find("Level-5"), std::string::npos)
      << annotation.status().message();
  fs::remove(path);
}

}  // namespace
}  // namespace tod
