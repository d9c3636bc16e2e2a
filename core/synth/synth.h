// Synthetic road scenes in the Lost and Found layout (issue 2): a calibrated pinhole camera over
// a road plane, so an obstacle's size and image row follow from its distance. For tests, demos
// and the default model only; the method must not be tuned to this generator.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

// Obstacle shapes (ALGORITHM.md has none; the issue asks for varied ones): boxes / bricks /
// planks with visible top and side faces, vertical cylinders (buckets, cans, posts), tyres
// standing (with a see-through hole) or lying, balls, and irregular flat-ish things (toys,
// bags, debris).
enum class SynthShape { kBox, kCylinder, kTyreStanding, kTyreLying, kBall, kIrregular };

// One obstacle in world coordinates (camera at X = 0, road plane Y = 0, Z forward, metres).
struct SynthObstacleSpec {
  SynthShape shape = SynthShape::kBox;
  double x_m = 0.0;      // lateral position of the footprint centre
  double z_m = 10.0;     // distance of the footprint centre
  double width_m = 0.3;  // across (ball / cylinder / tyre: diameter)
  double height_m = 0.3;
  double depth_m = 0.3;  // along the view direction before yaw
  double yaw_rad = 0.0;
  cv::Vec3f colour_bgr{60, 90, 160};  // 0..255, before shading and camera effects
  int label_class = 2;                // LAF labelIds obstacle class, 2..43
};

struct SynthParams {
  int width = 2048;
  int height = 1024;
  // Camera: horizon row as a fraction of the height, camera height above the road (m),
  // focal length in pixels as a fraction of the width.
  double horizon_frac = 0.40;
  double camera_height_m = 1.4;
  double focal_frac = 1.1;
  // Obstacles: count per frame, physical size and distance ranges.
  int min_obstacles = 1;
  int max_obstacles = 4;
  double min_size_m = 0.05;
  double max_size_m = 0.6;
  double min_distance_m = 5.0;
  double max_distance_m = 60.0;
  // Per-frame random variation of the camera (relative, e.g. 0.08 = +-8 % focal length and
  // camera height, +-0.08 * 0.25 of the height in horizon row). 0 = exactly the values above.
  double camera_jitter = 0.08;
  // Obstacles under this projected height (px) are not placed; drawn obstacles with fewer
  // visible pixels than min_visible_pixels are labelled ignore instead of obstacle.
  double min_obstacle_height_px = 4.0;
  int min_visible_pixels = 20;
  // Tests / demos: when set, exactly these obstacles are drawn instead of random ones.
  std::optional<std::vector<SynthObstacleSpec>> fixed_obstacles;
  // Frames per scene folder in WriteSynthDataset.
  int frames_per_scene = 10;
};

// What the generator knows about a drawn obstacle (for geometry checks and demos).
struct SynthObstacleInfo {
  SynthObstacleSpec spec;
  int instance_id = 0;  // class * 1000 + k; 0 when relabelled ignore (too few visible pixels)
  long long visible_pixels = 0;
};

struct SynthCameraInfo {
  double focal_px = 0;
  double center_x = 0;
  double horizon_row = 0;
  double camera_height_m = 0;
};

// WriteSynthDataset writes each frame's camera beside its labels, as
// gtCoarse/<split>/<scene>/<stem>_camera.json: the true horizon row the calibration is measured
// against (tod horizon).
inline constexpr const char* kSynthCameraSuffix = "_camera.json";
std::string SynthCameraJson(const SynthCameraInfo& camera);
// The camera written beside a synthetic frame whose image is at `image_path` (its
// leftImg8bit/.../<stem>_leftImg8bit.png); none when the frame has no such file.
std::optional<SynthCameraInfo> ReadSynthCamera(const std::string& image_path);

// A generated frame with the raw LAF annotation images it is written as.
struct SynthFrame {
  Sample sample;
  cv::Mat1w instance_ids;  // LAF _gtCoarse_instanceIds (16-bit)
  cv::Mat1b label_ids;     // LAF _gtCoarse_labelIds
  SynthCameraInfo camera;
  std::vector<SynthObstacleInfo> obstacles;
};

// As GenerateSynthFrame, with the annotation images and the scene facts.
SynthFrame GenerateSynthFrameDetailed(const SynthParams& params, std::uint64_t seed,
                                      const std::string& name);

// One frame, deterministic for (params, seed): image plus full ground truth.
Sample GenerateSynthFrame(const SynthParams& params, std::uint64_t seed, const std::string& name);

// Seed of frame `frame_index` (0-based over train then test) of a dataset written with
// `dataset_seed`: GenerateSynthFrame(params, SynthFrameSeed(s, i), stem) reproduces that frame.
std::uint64_t SynthFrameSeed(std::uint64_t dataset_seed, int frame_index);

// Writes `train_count` + `test_count` frames to `out_dir` in the LAF layout (scene folders,
// _leftImg8bit.png, _gtCoarse_labelIds.png, _gtCoarse_instanceIds.png). Scene folders
// synth_<scene> hold params.frames_per_scene frames each, stems synth_<scene>_<frame index>;
// train and test never share a scene. Errors name the path that could not be written.
Status WriteSynthDataset(const std::string& out_dir, const SynthParams& params, int train_count,
                         int test_count, std::uint64_t seed,
                         const std::function<void(int done, int total)>& progress = {});

}  // namespace tod
