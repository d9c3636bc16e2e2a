// Integers read from manifest.json are checked before nlohmann converts them (json_integers.h);
// the regression input is fuzz_manifest's finding (docs/service.md#found-and-fixed).
#include "core/pipeline/json_integers.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "core/pipeline/multilayer_regions.h"
#include "core/pipeline/pipeline_params.h"
#include "tests/test_env.h"

namespace tod {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TEST(JsonIntegers, OnlyIntegersInIntsRangeAreInts) {
  EXPECT_TRUE(IsJsonInt(json(0)));
  EXPECT_TRUE(IsJsonInt(json(std::numeric_limits<int>::max())));
  EXPECT_TRUE(IsJsonInt(json(std::numeric_limits<int>::min())));
  EXPECT_FALSE(IsJsonInt(json(std::int64_t{std::numeric_limits<int>::max()} + 1)));
  EXPECT_FALSE(IsJsonInt(json(std::int64_t{std::numeric_limits<int>::min()} - 1)));
  EXPECT_FALSE(IsJsonInt(json(std::numeric_limits<std::uint64_t>::max())));
  EXPECT_FALSE(IsJsonInt(json::parse("1.11e23")));
  EXPECT_FALSE(IsJsonInt(json::parse("4.0")));  // a float, however integral
  EXPECT_FALSE(IsJsonInt(json("4")));
  EXPECT_FALSE(IsJsonInt(json(true)));
  const Result<int> v = JsonToInt(json::parse("-7"), "x");
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(*v, -7);
  const Result<int> bad = JsonToInt(json::parse("1e30"), "layers");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("layers"), std::string::npos) << bad.status().message();
}

TEST(JsonIntegers, MembersFollowTheKindOfTheirDefaults) {
  const json defaults = {{"n", 3}, {"seed", std::uint64_t{1}}, {"ratio", 0.5}, {"in", {{"k", 2}}}};
  EXPECT_TRUE(CheckJsonIntegers(json::object(), defaults, "p: ").ok());
  EXPECT_TRUE(CheckJsonIntegers({{"n", -4}, {"ratio", 7}, {"other", 1.5}}, defaults, "p: ").ok());
  EXPECT_TRUE(
      CheckJsonIntegers({{"seed", std::numeric_limits<std::uint64_t>::max()}}, defaults, "p: ")
          .ok());
  EXPECT_FALSE(CheckJsonIntegers({{"n", 3.5}}, defaults, "p: ").ok());
  EXPECT_FALSE(CheckJsonIntegers({{"n", 4294967296}}, defaults, "p: ").ok());
  EXPECT_FALSE(CheckJsonIntegers({{"seed", -1}}, defaults, "p: ").ok());
  EXPECT_FALSE(CheckJsonIntegers({{"seed", 1e30}}, defaults, "p: ").ok());
  const Status nested = CheckJsonIntegers({{"in", {{"k", 1e300}}}}, defaults, "p: ");
  EXPECT_EQ(nested.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(nested.message().find("p: in.k"), std::string::npos) << nested.message();
}

TEST(JsonIntegers, PipelineParamsRefuseFloatsAndOverflowInIntegerFields) {
  EXPECT_FALSE(PipelineParamsFromJson({{"boxes", {{"max_boxes", 1e30}}}}).ok());
  EXPECT_FALSE(PipelineParamsFromJson({{"superpixels", {{"k", 4294967296}}}}).ok());
  EXPECT_FALSE(PipelineParamsFromJson({{"regions", {{"seed", -1}}}}).ok());
  const Result<PipelineParams> big_seed =
      PipelineParamsFromJson({{"regions", {{"seed", std::uint64_t{1} << 63}}}});
  ASSERT_TRUE(big_seed.ok()) << big_seed.status().message();
  EXPECT_EQ(big_seed->regions.seed, std::uint64_t{1} << 63);
}

// fuzz_manifest's input: a region corner of 111000000000000000000893, which JSON parses as a
// double (it fits no 64-bit integer) and get<int>() converted: undefined behaviour (UBSan).
TEST(JsonIntegers, FuzzerManifestWithAHugeRegionCornerIsRefused) {
  const fs::path input = fs::path(testing_env::SourceDir()) /
                         "tests/fuzz/corpus/fuzz_manifest/"
                         "crash-e9ef2d750707bae1d184589e2c9f8757c552208b";
  std::ifstream in(input);
  ASSERT_TRUE(in) << input;
  const json manifest = json::parse(in);
  const Result<MultilayerRegions> regions = MultilayerRegions::FromJson(manifest.at("regions"));
  ASSERT_FALSE(regions.ok());
  EXPECT_EQ(regions.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(regions.status().message().find("ints"), std::string::npos)
      << regions.status().message();
  json regions_json = manifest.at("regions");
  regions_json["image_width"] = 2048.5;
  EXPECT_FALSE(MultilayerRegions::FromJson(regions_json).ok());
}

}  // namespace
}  // namespace tod
