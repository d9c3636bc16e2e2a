// The pure parts of `tod bench` (core/pipeline/frame_bench.h): which files are frames, and the
// median / p90 / max it reports. The measurement itself runs end to end in
// tests/cli/bench_cli_test.cc.
#include "core/evaluation/frame_bench.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace tod {
namespace {
namespace fs = std::filesystem;

TEST(FrameBenchTest, SpreadIsMedianNearestRankP90AndMax) {
  const Spread odd = SpreadOf({5, 1, 3});
  EXPECT_DOUBLE_EQ(odd.median, 3);
  EXPECT_DOUBLE_EQ(odd.p90, 5);  // rank ceil(2.7) = 3
  EXPECT_DOUBLE_EQ(odd.max, 5);
  const Spread even = SpreadOf({4, 1, 2, 3});
  EXPECT_DOUBLE_EQ(even.median, 2.5);
  EXPECT_DOUBLE_EQ(even.p90, 4);  // rank ceil(3.6) = 4
  std::vector<double> ten;
  for (int i = 10; i >= 1; --i) ten.push_back(i);
  const Spread deciles = SpreadOf(ten);
  EXPECT_DOUBLE_EQ(deciles.p90, 9);  // rank 9 of 10: one frame above it
  EXPECT_DOUBLE_EQ(deciles.max, 10);
  const Spread one = SpreadOf({7});
  EXPECT_DOUBLE_EQ(one.median, 7);
  EXPECT_DOUBLE_EQ(one.p90, 7);
  const Spread none = SpreadOf({});
  EXPECT_DOUBLE_EQ(none.median, 0);
  EXPECT_DOUBLE_EQ(none.max, 0);
}

TEST(FrameBenchTest, ListsImagesRecursivelySortedWhateverTheExtensionCase) {
  const fs::path dir =
      fs::temp_directory_path() / ("tod_frame_bench_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "b" / "c");
  for (const char* name :
       {"z.png", "a.JPG", "b/c/d.jpeg", "b/e.webp", "b/notes.txt", "b/f.png.json"})
    std::ofstream(dir / name) << "x";
  fs::create_directories(dir / "g.png");  // a directory named like a frame is not one
  const auto frames = ListBenchFrames(dir.string());
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  const std::vector<std::string> expected = {(dir / "a.JPG").string(),
                                             (dir / "b/c/d.jpeg").string(),
                                             (dir / "b/e.webp").string(), (dir / "z.png").string()};
  EXPECT_EQ(*frames, expected);
  fs::remove_all(dir);
  EXPECT_EQ(ListBenchFrames(dir.string()).status().code(), StatusCode::kNotFound);
}

TEST(FrameBenchTest, StageNamesAreTheContract) {
  const std::vector<std::string> expected = {"decode",     "calibration", "edges",    "superpixels", "occlusion",
                                             "proposals",  "features", "regression",  "map",
                                             "encode_map", "total"};
  EXPECT_EQ(BenchStageNames(), expected);
}

}  // namespace
}  // namespace tod
