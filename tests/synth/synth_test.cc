// Synthetic generator: what it writes is what the LAF reader reads back; it is deterministic;
// obstacles obey the pinhole geometry computed by hand below; it works at any size.
#include "core/synth/synth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include "core/data/laf_reader.h"
#include "tests/data/temp_dir.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

SynthParams SmallParams(int width, int height) {
  SynthParams p;
  p.width = width;
  p.height = height;
  p.frames_per_scene = 2;
  return p;
}

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void ExpectSameSample(const Sample& expected, const Sample& actual) {
  ASSERT_EQ(expected.image.size(), actual.image.size());
  EXPECT_EQ(cv::norm(expected.image, actual.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(expected.road, actual.road, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(expected.obstacle, actual.obstacle, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(expected.ignore, actual.ignore, cv::NORM_INF), 0.0);
  ASSERT_EQ(expected.instances.size(), actual.instances.size());
  for (std::size_t k = 0; k < expected.instances.size(); ++k) {
    const ObstacleInstance& e = expected.instances[k];
    const ObstacleInstance& a = actual.instances[k];
    EXPECT_EQ(e.id, a.id);
    EXPECT_EQ(e.box, a.box);
    EXPECT_EQ(e.pixel_count(), a.pixel_count());
    ASSERT_EQ(e.mask.size(), a.mask.size());
    EXPECT_EQ(cv::norm(e.mask, a.mask, cv::NORM_INF), 0.0);
  }
}

TEST(Synth, WrittenDatasetReadsBackWithTheSameInstances) {
  tod::testing::TempDir dir;
  const SynthParams params = SmallParams(512, 256);
  constexpr std::uint64_t kSeed = 7;
  int last_done = 0, calls = 0;
  const Status status = WriteSynthDataset(dir.str(), params, 3, 2, kSeed, [&](int done, int total) {
    EXPECT_EQ(total, 5);
    EXPECT_EQ(done, last_done + 1);
    last_done = done;
    ++calls;
  });
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(calls, 5);
  ASSERT_TRUE(LooksLikeLaf(dir.str()));

  // Train frames 0..2 in scenes 0, 0, 1; test frames 3..4 start a new scene (2).
  EXPECT_TRUE(
      fs::exists(dir.path() / "leftImg8bit/train/synth_000/synth_000_000000_leftImg8bit.png"));
  EXPECT_TRUE(
      fs::exists(dir.path() / "leftImg8bit/train/synth_001/synth_001_000002_leftImg8bit.png"));
  EXPECT_TRUE(
      fs::exists(dir.path() / "gtCoarse/test/synth_002/synth_002_000004_gtCoarse_instanceIds.png"));

  int instances_seen = 0;
  int frame_index = 0;
  for (const char* split : {"train", "test"}) {
    auto dataset = OpenLafDataset(dir.str(), split);
    ASSERT_TRUE(dataset.ok()) << dataset.status().message();
    ASSERT_EQ((*dataset)->size(), std::string(split) == "train" ? 3u : 2u);
    for (std::size_t i = 0; i < (*dataset)->size(); ++i, ++frame_index) {
      const std::string stem = (*dataset)->name(i);
      EXPECT_TRUE(std::regex_match(stem, std::regex("synth_\\d{3}_\\d{6}"))) << stem;
      auto read = (*dataset)->Load(i);
      ASSERT_TRUE(read.ok()) << read.status().message();
      const Sample generated = GenerateSynthFrame(params, SynthFrameSeed(kSeed, frame_index), stem);
      ExpectSameSample(generated, *read);
      instances_seen += static_cast<int>(read->instances.size());
    }
  }
  EXPECT_GT(instances_seen, 0) << "the round trip must have compared some obstacles";
}

TEST(Synth, SameSeedSameBytesDifferentSeedDifferentImage) {
  tod::testing::TempDir dir;
  const SynthParams params = SmallParams(256, 128);
  ASSERT_TRUE(WriteSynthDataset((dir.path() / "a").string(), params, 2, 1, 42).ok());
  ASSERT_TRUE(WriteSynthDataset((dir.path() / "b").string(), params, 2, 1, 42).ok());
  ASSERT_TRUE(WriteSynthDataset((dir.path() / "c").string(), params, 2, 1, 43).ok());
  int files = 0, differing_from_c = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir.path() / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), dir.path() / "a");
    ++files;
    EXPECT_EQ(FileBytes(entry.path()), FileBytes(dir.path() / "b" / rel)) << rel;
    if (FileBytes(entry.path()) != FileBytes(dir.path() / "c" / rel)) ++differing_from_c;
  }
  EXPECT_EQ(files, 12);            // 3 frames x (image, labelIds, instanceIds, camera truth)
  EXPECT_GE(differing_from_c, 3);  // at least every image differs

  const Sample x = GenerateSynthFrame(params, 5, "x");
  const Sample y = GenerateSynthFrame(params, 5, "x");
  const Sample z = GenerateSynthFrame(params, 6, "x");
  EXPECT_EQ(cv::norm(x.image, y.image, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(x.image, z.image, cv::NORM_L1), 0.0);
}

// A 0.4 m cube (yaw 0) at 10 m and at 20 m, camera without jitter. With focal f, principal
// column cx, horizon row r0 and camera height H, the cube's image box runs from row
// r0 + f (H - 0.4) / (z + 0.2) (top back edge) to r0 + f H / (z - 0.2) (bottom front edge);
// columns are the extremes of cx + f X / Z over its corners X = x +- 0.2, Z = z +- 0.2 (off
// centre, the side face facing the camera widens the box).
TEST(Synth, ObstacleSizeAndRowFollowPinholeGeometry) {
  SynthParams params = SmallParams(512, 256);
  params.camera_jitter = 0.0;
  SynthObstacleSpec near_cube;
  near_cube.shape = SynthShape::kBox;
  near_cube.width_m = near_cube.depth_m = near_cube.height_m = 0.4;
  near_cube.yaw_rad = 0.0;
  near_cube.x_m = -0.8;
  near_cube.z_m = 10.0;
  near_cube.label_class = 5;
  SynthObstacleSpec far_cube = near_cube;
  far_cube.x_m = 0.8;
  far_cube.z_m = 20.0;
  far_cube.label_class = 7;
  params.fixed_obstacles = std::vector<SynthObstacleSpec>{near_cube, far_cube};

  const SynthFrame frame = GenerateSynthFrameDetailed(params, 11, "geometry");
  const double f = 1.1 * 512, r0 = 0.4 * 256, H = 1.4, cx = 256;
  EXPECT_DOUBLE_EQ(frame.camera.focal_px, f);
  EXPECT_DOUBLE_EQ(frame.camera.horizon_row, r0);
  ASSERT_EQ(frame.sample.instances.size(), 2u);
  const ObstacleInstance& near_box = frame.sample.instances[0];  // id 5001 < 7002
  const ObstacleInstance& far_box = frame.sample.instances[1];
  EXPECT_EQ(near_box.id, 5001);
  EXPECT_EQ(far_box.id, 7002);

  for (const auto& [inst, spec] :
       {std::pair{&near_box, near_cube}, std::pair{&far_box, far_cube}}) {
    const double z = spec.z_m;
    const double top = r0 + f * (H - 0.4) / (z + 0.2);
    const double bottom = r0 + f * H / (z - 0.2);
    const double x0 = spec.x_m - 0.2, x1 = spec.x_m + 0.2;
    const double left = std::min(cx + f * x0 / (z - 0.2), cx + f * x0 / (z + 0.2));
    const double right = std::max(cx + f * x1 / (z - 0.2), cx + f * x1 / (z + 0.2));
    EXPECT_NEAR(inst->box.y, top, 1.0) << "z=" << z;
    EXPECT_NEAR(inst->box.bottom(), bottom, 1.0) << "z=" << z;
    EXPECT_NEAR(inst->box.x, left, 1.0) << "z=" << z;
    EXPECT_NEAR(inst->box.right(), right, 1.0) << "z=" << z;
  }
  // Twice as far: about half the size, and higher in the image (closer to the horizon).
  const double ratio = static_cast<double>(near_box.box.h) / far_box.box.h;
  EXPECT_GT(ratio, 1.7);
  EXPECT_LT(ratio, 2.4);
  EXPECT_LT(far_box.box.bottom(), near_box.box.bottom());
  EXPECT_GT(near_box.pixel_count(), 3 * far_box.pixel_count());
}

TEST(Synth, StandingTyreShowsRoadThroughItsHole) {
  SynthParams params = SmallParams(512, 256);
  params.camera_jitter = 0.0;
  SynthObstacleSpec tyre;
  tyre.shape = SynthShape::kTyreStanding;
  tyre.width_m = tyre.height_m = 0.6;
  tyre.depth_m = 0.15;
  tyre.yaw_rad = 0.0;  // axle along the view direction: the hole faces the camera
  tyre.x_m = 0.0;
  tyre.z_m = 6.0;
  // A rimless tyre is drawn with probability 0.6; find a seed where the hole is open, which is
  // visible in the labels as road at the tyre's centre.
  const double f = 1.1 * 512, r0 = 0.4 * 256, H = 1.4, cx = 256;
  const int u = static_cast<int>(cx), v = static_cast<int>(r0 + f * (H - 0.3) / 6.0);
  const int u_tread = static_cast<int>(cx + f * 0.26 / 6.0);
  params.fixed_obstacles = std::vector<SynthObstacleSpec>{tyre};
  int open = 0, closed = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const SynthFrame frame = GenerateSynthFrameDetailed(params, seed, "tyre");
    ASSERT_EQ(frame.sample.instances.size(), 1u);
    EXPECT_EQ(frame.sample.obstacle(v, u_tread), 255) << "seed " << seed;  // the tread
    if (frame.sample.obstacle(v, u) == 0) {
      EXPECT_EQ(frame.instance_ids(v, u), 1000) << "seed " << seed;  // road seen through the hole
      ++open;
    } else {
      ++closed;
    }
  }
  EXPECT_GT(open, 0);
  EXPECT_GT(closed, 0);
}

TEST(Synth, TinyObstaclesAreLabelledIgnore) {
  SynthParams params = SmallParams(256, 128);
  params.camera_jitter = 0.0;
  SynthObstacleSpec pebble;
  pebble.shape = SynthShape::kBall;
  pebble.width_m = pebble.height_m = pebble.depth_m = 0.1;
  pebble.z_m = 25.0;  // f = 281.6: about 1 px across, far below 20 visible pixels
  params.fixed_obstacles = std::vector<SynthObstacleSpec>{pebble};
  const SynthFrame frame = GenerateSynthFrameDetailed(params, 3, "tiny");
  ASSERT_EQ(frame.obstacles.size(), 1u);
  EXPECT_EQ(frame.obstacles[0].instance_id, 0);
  EXPECT_LT(frame.obstacles[0].visible_pixels, 20);
  EXPECT_TRUE(frame.sample.instances.empty());
  EXPECT_EQ(cv::countNonZero(frame.sample.obstacle), 0);
  EXPECT_EQ(cv::countNonZero(frame.instance_ids > 1000), 0);
}

TEST(Synth, WorksAtAnySizeWithRoadInTheLowerMiddle) {
  for (const cv::Size size : {cv::Size(256, 128), cv::Size(512, 256), cv::Size(96, 48)}) {
    const SynthParams params = SmallParams(size.width, size.height);
    int frames_with_obstacles = 0;
    for (std::uint64_t seed = 0; seed < 6; ++seed) {
      const SynthFrame frame = GenerateSynthFrameDetailed(params, seed, "s");
      const Sample& s = frame.sample;
      ASSERT_EQ(s.image.size(), size);
      ASSERT_EQ(s.road.size(), size);
      ASSERT_EQ(frame.instance_ids.size(), size);
      // Every pixel is exactly one of road / obstacle / ignore.
      EXPECT_EQ(
          cv::countNonZero(s.road) + cv::countNonZero(s.obstacle) + cv::countNonZero(s.ignore),
          size.area());
      // No road above the horizon; the road covers much of the bottom third's middle half.
      const int horizon = static_cast<int>(std::ceil(frame.camera.horizon_row));
      EXPECT_EQ(cv::countNonZero(s.road.rowRange(0, horizon)), 0);
      const cv::Mat1b lower_middle =
          s.road(cv::Rect(size.width / 4, size.height * 2 / 3, size.width / 2, size.height / 3));
      EXPECT_GT(cv::countNonZero(lower_middle), lower_middle.total() / 3)
          << size << " seed " << seed;
      EXPECT_LE(s.instances.size(), 4u);
      long long instance_pixels = 0;
      for (const ObstacleInstance& inst : s.instances) {
        EXPECT_GE(inst.pixel_count(), params.min_visible_pixels);
        EXPECT_GE(inst.id, 2001);
        EXPECT_LE(inst.id / 1000, 43);
        EXPECT_EQ(frame.label_ids(inst.box.y, inst.box.x) == inst.id / 1000,
                  inst.mask(0, 0) == 255);  // labelIds carries the class where the instance is
        instance_pixels += inst.pixel_count();
      }
      EXPECT_EQ(instance_pixels, cv::countNonZero(s.obstacle));
      if (!s.instances.empty()) ++frames_with_obstacles;
    }
    if (size.width >= 256) {
      EXPECT_GE(frames_with_obstacles, 4) << size;
    }
  }
}

TEST(Synth, WriteErrorsNameThePath) {
  tod::testing::TempDir dir;
  const fs::path blocker = dir.path() / "not_a_dir";
  std::ofstream(blocker) << "x";
  const Status s = WriteSynthDataset(blocker.string(), SmallParams(64, 32), 1, 0, 1);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find(blocker.string()), std::string::npos) << s.message();

  const Status tiny = WriteSynthDataset(dir.str(), SmallParams(8, 8), 1, 0, 1);
  ASSERT_FALSE(tiny.ok());
  EXPECT_EQ(tiny.code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace tod
