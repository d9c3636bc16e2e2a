#include "core/base/binary_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/checksum.h"

namespace tod {
namespace {

constexpr std::string_view kMagic("TESTMAG\0", 8);

// One of everything the writer can write, in a fixed order that Decode reads back.
std::string EncodeSample() {
  BinaryWriter out;
  out.Header(kMagic, 3);
  out.U8(0xAB);
  out.U32(0xDEADBEEF);
  out.U64(0x0123456789ABCDEFULL);
  out.I32(-42);
  out.F32(-1.5f);
  out.F64(std::numeric_limits<double>::denorm_min());
  out.String("obstacle");
  out.Vector<float>(std::vector<float>{1.f, -0.f, std::numeric_limits<float>::infinity()});
  out.Vector<std::uint64_t>(std::vector<std::uint64_t>{7, 1ULL << 40});
  out.Vector<std::int32_t>(std::vector<std::int32_t>{});
  return std::move(out).Release();
}

struct Sample {
  std::uint8_t u8 = 0;
  std::uint32_t u32 = 0;
  std::uint64_t u64 = 0;
  std::int32_t i32 = 0;
  float f32 = 0;
  double f64 = 0;
  std::string text;
  std::vector<float> floats;
  std::vector<std::uint64_t> longs;
  std::vector<std::int32_t> none;
};

// The convention of binary_io.h, so the sample also exercises EncodeModel / DecodeModel.
struct SampleModel {
  Sample value;
  Status Save(BinaryWriter& out) const {
    out.Raw(EncodeSample());
    return Status::Ok();
  }
  static Result<SampleModel> Load(BinaryReader& in) {
    if (Status s = in.Header(kMagic, 3, "test file"); !s.ok()) return s;
    SampleModel m;
    m.value.u8 = in.U8("u8");
    m.value.u32 = in.U32("u32");
    m.value.u64 = in.U64("u64");
    m.value.i32 = in.I32("i32");
    m.value.f32 = in.F32("f32");
    m.value.f64 = in.F64("f64");
    m.value.text = in.String("text", 100);
    m.value.floats = in.Vector<float>("floats", 100);
    m.value.longs = in.Vector<std::uint64_t>("longs", 100);
    m.value.none = in.Vector<std::int32_t>("none", 100);
    if (!in.ok()) return in.status();
    return m;
  }
};

TEST(BinaryIo, RoundTripsEveryType) {
  const std::string bytes = EncodeSample();
  const Result<SampleModel> model = DecodeModel<SampleModel>(bytes, "sample.bin");
  ASSERT_TRUE(model.ok()) << model.status().message();
  const Sample& s = model->value;
  EXPECT_EQ(s.u8, 0xAB);
  EXPECT_EQ(s.u32, 0xDEADBEEFu);
  EXPECT_EQ(s.u64, 0x0123456789ABCDEFULL);
  EXPECT_EQ(s.i32, -42);
  EXPECT_EQ(s.f32, -1.5f);
  EXPECT_EQ(s.f64, std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(s.text, "obstacle");
  ASSERT_EQ(s.floats.size(), 3u);
  EXPECT_EQ(s.floats[0], 1.f);
  EXPECT_TRUE(std::signbit(s.floats[1]));  // bit patterns survive, the sign of zero too
  EXPECT_TRUE(std::isinf(s.floats[2]));
  EXPECT_EQ(s.longs, (std::vector<std::uint64_t>{7, 1ULL << 40}));
  EXPECT_TRUE(s.none.empty());
  EXPECT_EQ(EncodeModel(*model).value(), bytes);
}

TEST(BinaryIo, EncodingIsLittleEndianAndFixedWidth) {
  BinaryWriter out;
  out.U32(0x04030201);
  out.I32(-2);
  out.U64(0x0807060504030201ULL);
  out.F32(1.f);  // 0x3F800000
  out.U8(9);
  out.String("ab");
  EXPECT_EQ(out.bytes(), std::string("\x01\x02\x03\x04"
                                     "\xFE\xFF\xFF\xFF"
                                     "\x01\x02\x03\x04\x05\x06\x07\x08"
                                     "\x00\x00\x80\x3F"
                                     "\x09"
                                     "\x02\x00\x00\x00\x00\x00\x00\x00"
                                     "ab",
                                     31));
  EXPECT_EQ(out.BytesSince(29), "ab");
}

TEST(BinaryIo, TruncationAtEveryOffsetFailsCleanly) {
  const std::string bytes = EncodeSample();
  for (std::size_t length = 0; length < bytes.size(); ++length) {
    const Result<SampleModel> model =
        DecodeModel<SampleModel>(std::string_view(bytes).substr(0, length), "cut.bin");
    ASSERT_FALSE(model.ok()) << "length " << length;
    EXPECT_EQ(model.status().code(), StatusCode::kDataLoss) << model.status().message();
    EXPECT_EQ(model.status().message().rfind("cut.bin: truncated", 0), 0u)
        << model.status().message();
  }
}

TEST(BinaryIo, FirstFailureSticksAndLaterReadsAreZero) {
  BinaryReader in(std::string_view("\x05\x00", 2), "short.bin");
  EXPECT_EQ(in.U32("first field"), 0u);
  EXPECT_FALSE(in.ok());
  EXPECT_EQ(in.U8("second field"), 0);  // would fit, but the reader has failed
  EXPECT_TRUE(in.String("third field").empty());
  EXPECT_NE(in.status().message().find("first field"), std::string::npos);
  EXPECT_NE(in.status().message().find("offset 0"), std::string::npos);
  EXPECT_EQ(in.position(), 0u);
}

TEST(BinaryIo, OversizeLengthsAreRefusedBeforeAllocating) {
  // A count the bytes left cannot hold: refused whatever the limit, without reserving for it.
  for (const std::uint64_t count :
       {std::uint64_t{9}, std::uint64_t{1} << 40, std::numeric_limits<std::uint64_t>::max()}) {
    BinaryWriter out;
    out.U64(count);
    out.F64(1.0);  // 8 bytes left: one double or an 8-character string, not more
    {
      BinaryReader in(out.bytes(), "vec.bin");
      EXPECT_TRUE(in.Vector<double>("doubles").empty());
      EXPECT_EQ(in.status().code(), StatusCode::kDataLoss);
      EXPECT_NE(in.status().message().find("doubles claims"), std::string::npos)
          << in.status().message();
    }
    {
      BinaryReader in(out.bytes(), "str.bin");
      EXPECT_TRUE(in.String("name").empty());
      EXPECT_EQ(in.status().code(), StatusCode::kDataLoss);
    }
  }
  // A count that fits the bytes but not the caller's limit.
  BinaryWriter out;
  out.Vector<std::uint8_t>(std::vector<std::uint8_t>(10, 1));
  out.String("0123456789");
  BinaryReader limited(out.bytes(), "limit.bin");
  EXPECT_TRUE(limited.Vector<std::uint8_t>("bytes", 9).empty());
  EXPECT_NE(limited.status().message().find("limit 9"), std::string::npos);
  BinaryReader exact(out.bytes(), "limit.bin");
  EXPECT_EQ(exact.Vector<std::uint8_t>("bytes", 10).size(), 10u);
  EXPECT_TRUE(exact.String("name", 9).empty());
  EXPECT_FALSE(exact.ok());
  // Expect guards a loader's own counts the same way, overflow included.
  BinaryReader in(std::string_view("12345678", 8), "e.bin");
  EXPECT_TRUE(in.Expect(2, 4, "pairs"));
  EXPECT_FALSE(in.Expect(std::numeric_limits<std::uint64_t>::max() / 2, 4, "pairs"));
  EXPECT_EQ(in.status().code(), StatusCode::kDataLoss);
}

TEST(BinaryIo, HeaderTellsWrongKindFromWrongVersion) {
  BinaryWriter other_kind;
  other_kind.Header(std::string_view("OTHERMAG", 8), 3);
  BinaryReader kind(other_kind.bytes(), "k.bin");
  const Status bad_magic = kind.Header(kMagic, 3, "test file");
  EXPECT_EQ(bad_magic.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bad_magic.message(), "k.bin: not a test file (bad magic number)");

  BinaryWriter other_version;
  other_version.Header(kMagic, 4);
  BinaryReader version(other_version.bytes(), "v.bin");
  const Status bad_version = version.Header(kMagic, 3, "test file");
  EXPECT_EQ(bad_version.code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(bad_version.message(), "v.bin: test file format version 4, this build reads version 3");
  EXPECT_EQ(version.status().code(), StatusCode::kFailedPrecondition);  // one status path
}

TEST(BinaryIo, LeftOverBytesAndStructuralProblemsAreDataLoss) {
  const Result<SampleModel> extra = DecodeModel<SampleModel>(EncodeSample() + "x", "x.bin");
  ASSERT_FALSE(extra.ok());
  EXPECT_EQ(extra.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(extra.status().message().find("1 unexpected bytes"), std::string::npos);

  BinaryReader in(std::string_view("abc", 3), "c.bin");
  const Status corrupt = in.Corrupt("node 3 points backwards");
  EXPECT_EQ(corrupt.message(), "c.bin: node 3 points backwards");
  EXPECT_EQ(in.Corrupt("a later problem").message(), corrupt.message());  // the first one stays
}

TEST(BinaryIo, BytesSinceCoversWhatWasReadForChecksums) {
  BinaryWriter out;
  out.U32(1);
  const std::size_t start = out.size();
  out.String("payload");
  out.U64(Fnv1a64(out.BytesSince(start)));
  BinaryReader in(out.bytes(), "sum.bin");
  EXPECT_EQ(in.U32("skip"), 1u);
  const std::size_t from = in.position();
  EXPECT_EQ(in.String("payload"), "payload");
  const std::uint64_t expected = Fnv1a64(in.BytesSince(from));
  EXPECT_EQ(in.U64("checksum"), expected);
  EXPECT_EQ(in.remaining(), 0u);
  EXPECT_TRUE(in.ExpectEnd().ok());
}

TEST(Checksum, Fnv1a64KnownValues) {
  EXPECT_EQ(Fnv1a64(""), 0xCBF29CE484222325ULL);
  EXPECT_EQ(Fnv1a64("a"), 0xAF63DC4C8601EC8CULL);
}

}  // namespace
}  // namespace tod
