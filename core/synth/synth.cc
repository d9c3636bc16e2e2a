// Synthetic Lost-and-Found-style frames (issue 2). Drawing order: sky and ground, road markings
// and hard negatives, then everything standing (clutter and obstacles) far to near, so the
// labels are exactly the visible pixels. Then the camera turns the scene into 8-bit BGR.
#include "core/synth/synth.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>
#include <utility>

#include "core/base/atomic_file.h"
#include "core/synth/synth_canvas.h"
#include "core/synth/synth_effects.h"
#include "core/synth/synth_obstacles.h"
#include "core/synth/synth_rng.h"
#include "core/synth/synth_scene.h"

namespace tod {
namespace {

namespace fs = std::filesystem;
using synth::Canvas;
using synth::Labels;
using synth::Rng;

// Smallest frame the layout code is meant for; smaller requests are enlarged to it.
constexpr int kMinSide = 32;

SynthParams Sanitised(SynthParams p) {
  p.width = std::max(p.width, kMinSide);
  p.height = std::max(p.height, kMinSide);
  p.min_obstacles = std::max(0, p.min_obstacles);
  p.max_obstacles = std::max(p.min_obstacles, p.max_obstacles);
  p.min_size_m = std::max(0.005, p.min_size_m);
  p.max_size_m = std::max(p.min_size_m, p.max_size_m);
  p.min_distance_m = std::max(0.5, p.min_distance_m);
  p.max_distance_m = std::max(p.min_distance_m, p.max_distance_m);
  return p;
}

// Masks and instances read off the finished label image (its own code, independent of the LAF
// reader, so the round-trip test compares two implementations).
Sample SampleFromLabels(const cv::Mat1w& instance_ids, const std::vector<int>& obstacle_ids) {
  Sample s;
  s.road = instance_ids == synth::kRoadInstanceId;
  s.obstacle = instance_ids > synth::kRoadInstanceId;
  s.ignore = instance_ids < synth::kRoadInstanceId;
  std::vector<int> ids = obstacle_ids;
  std::sort(ids.begin(), ids.end());
  for (int id : ids) {
    const cv::Mat1b mask = instance_ids == id;
    const cv::Rect box = cv::boundingRect(mask);
    if (box.area() == 0) continue;
    ObstacleInstance instance;
    instance.id = id;
    instance.box = Box::FromRect(box);
    instance.mask = mask(box).clone();
    s.instances.push_back(std::move(instance));
  }
  return s;
}

std::string SceneName(int scene) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "synth_%03d", scene);
  return buf;
}

std::string FrameStem(int scene, int frame) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "_%06d", frame);
  return SceneName(scene) + buf;
}

Status WritePng(const fs::path& path, const cv::Mat& image) {
  try {
    if (!cv::imwrite(path.string(), image, {cv::IMWRITE_PNG_COMPRESSION, 3})) {
      return Status::Unavailable("cannot write " + path.string());
    }
  } catch (const cv::Exception& e) {
    return Status::Unavailable("cannot write " + path.string() + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace

SynthFrame GenerateSynthFrameDetailed(const SynthParams& raw_params, std::uint64_t seed,
                                      const std::string& name) {
  const SynthParams params = Sanitised(raw_params);
  const cv::Size size(params.width, params.height);
  // One child generator per part of the scene: changing how one part draws does not reshuffle
  // the others.
  Rng root(seed);
  Rng layout_rng = root.Fork(), texture_rng = root.Fork(), decal_rng = root.Fork();
  Rng clutter_rng = root.Fork(), obstacle_rng = root.Fork(), draw_rng = root.Fork();
  Rng camera_rng = root.Fork();

  const synth::SceneLayout layout = synth::SampleLayout(params, layout_rng);
  Canvas canvas(size);
  canvas.detail = synth::FractalNoise(size, size.width / 6.0, 7, texture_rng);
  synth::DrawSkyAndGround(canvas, layout, texture_rng);
  synth::DrawRoadMarkings(canvas, layout, decal_rng);
  synth::DrawHardNegatives(canvas, layout, decal_rng);

  std::vector<synth::StandingItem> items = synth::SampleClutter(layout, clutter_rng);
  const std::vector<SynthObstacleSpec> specs =
      params.fixed_obstacles ? *params.fixed_obstacles
                             : synth::SampleObstacles(params, layout, obstacle_rng);
  SynthFrame frame;
  for (std::size_t k = 0; k < specs.size(); ++k) {
    SynthObstacleInfo info;
    info.spec = specs[k];
    info.spec.label_class = std::clamp(info.spec.label_class, 2, 43);
    info.instance_id = info.spec.label_class * 1000 + static_cast<int>(k) + 1;
    const Labels labels{static_cast<std::uint16_t>(info.instance_id),
                        static_cast<std::uint8_t>(info.spec.label_class)};
    items.push_back({synth::NearestDistance(info.spec),
                     [&layout, spec = info.spec, labels, rng = draw_rng.Fork()](Canvas& c) mutable {
                       synth::DrawObstacle(c, layout, spec, labels, rng);
                     }});
    frame.obstacles.push_back(info);
  }
  std::stable_sort(items.begin(), items.end(),
                   [](const synth::StandingItem& a, const synth::StandingItem& b) {
                     return a.nearest_m > b.nearest_m;
                   });
  for (synth::StandingItem& item : items) item.draw(canvas);

  // Obstacles almost entirely hidden (or sub-20-pixel) are not fair targets: ignore them.
  std::vector<int> kept_ids;
  for (SynthObstacleInfo& info : frame.obstacles) {
    const cv::Mat1b mask = canvas.instance_ids == info.instance_id;
    info.visible_pixels = cv::countNonZero(mask);
    if (info.visible_pixels < params.min_visible_pixels) {
      canvas.instance_ids.setTo(0, mask);
      canvas.label_ids.setTo(0, mask);
      info.instance_id = 0;
    } else {
      kept_ids.push_back(info.instance_id);
    }
  }

  frame.sample = SampleFromLabels(canvas.instance_ids, kept_ids);
  frame.sample.name = name;
  frame.sample.image_path = "synth:" + name;
  frame.sample.image = synth::ApplyCameraEffects(
      canvas.colour, synth::SampleCameraEffects(camera_rng, size.width / 2048.0));
  frame.instance_ids = canvas.instance_ids;
  frame.label_ids = canvas.label_ids;
  frame.camera = {layout.camera.focal_px, layout.camera.center_x, layout.camera.horizon_row,
                  layout.camera.height_m};
  return frame;
}

Sample GenerateSynthFrame(const SynthParams& params, std::uint64_t seed, const std::string& name) {
  return GenerateSynthFrameDetailed(params, seed, name).sample;
}

std::uint64_t SynthFrameSeed(std::uint64_t dataset_seed, int frame_index) {
  return synth::MixSeed(dataset_seed ^ synth::MixSeed(static_cast<std::uint64_t>(frame_index) + 1));
}

std::string SynthCameraJson(const SynthCameraInfo& camera) {
  char text[256];
  std::snprintf(text, sizeof text,
                "{\"focal_px\": %.3f, \"center_x\": %.3f, \"horizon_row\": %.3f, "
                "\"camera_height_m\": %.4f}\n",
                camera.focal_px, camera.center_x, camera.horizon_row, camera.camera_height_m);
  return text;
}

std::optional<SynthCameraInfo> ReadSynthCamera(const std::string& image_path) {
  const std::string image_suffix = "_leftImg8bit.png";
  const std::size_t dir = image_path.rfind("leftImg8bit/");
  if (dir == std::string::npos || image_path.size() < image_suffix.size() ||
      image_path.compare(image_path.size() - image_suffix.size(), image_suffix.size(),
                         image_suffix) != 0)
    return std::nullopt;
  std::string path = image_path.substr(0, image_path.size() - image_suffix.size());
  path.replace(dir, std::string("leftImg8bit").size(), "gtCoarse");
  std::ifstream in(path + kSynthCameraSuffix);
  if (!in) return std::nullopt;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object() || !j.contains("horizon_row") || !j["horizon_row"].is_number())
    return std::nullopt;
  SynthCameraInfo camera;
  camera.focal_px = j.value("focal_px", 0.0);
  camera.center_x = j.value("center_x", 0.0);
  camera.horizon_row = j["horizon_row"].get<double>();
  camera.camera_height_m = j.value("camera_height_m", 0.0);
  return camera;
}

Status WriteSynthDataset(const std::string& out_dir, const SynthParams& params, int train_count,
                         int test_count, std::uint64_t seed,
                         const std::function<void(int done, int total)>& progress) {
  if (out_dir.empty()) return Status::InvalidArgument("synth: --out directory is empty");
  if (train_count < 0 || test_count < 0) {
    return Status::InvalidArgument("synth: --train and --test must be >= 0");
  }
  if (params.width < kMinSide || params.height < kMinSide) {
    return Status::InvalidArgument("synth: --width and --height must be >= " +
                                   std::to_string(kMinSide));
  }
  if (params.frames_per_scene < 1) {
    return Status::InvalidArgument("synth: frames_per_scene must be >= 1");
  }
  const int total = train_count + test_count;
  int done = 0;
  int scene_base = 0;  // train and test never share a scene folder
  for (const auto& [split, count] : {std::pair<const char*, int>{"train", train_count},
                                     std::pair<const char*, int>{"test", test_count}}) {
    for (int i = 0; i < count; ++i) {
      const int scene = scene_base + i / params.frames_per_scene;
      const int global_index = done;
      const std::string stem = FrameStem(scene, global_index);
      const fs::path image_dir = fs::path(out_dir) / "leftImg8bit" / split / SceneName(scene);
      const fs::path gt_dir = fs::path(out_dir) / "gtCoarse" / split / SceneName(scene);
      std::error_code ec;
      for (const fs::path& dir : {image_dir, gt_dir}) {
        fs::create_directories(dir, ec);
        if (ec) return Status::Unavailable("cannot create " + dir.string() + ": " + ec.message());
      }
      SynthFrame frame =
          GenerateSynthFrameDetailed(params, SynthFrameSeed(seed, global_index), stem);
      Status s = WritePng(image_dir / (stem + "_leftImg8bit.png"), frame.sample.image);
      if (s.ok()) s = WritePng(gt_dir / (stem + "_gtCoarse_labelIds.png"), frame.label_ids);
      if (s.ok()) s = WritePng(gt_dir / (stem + "_gtCoarse_instanceIds.png"), frame.instance_ids);
      if (s.ok())
        s = WriteFileAtomically((gt_dir / (stem + kSynthCameraSuffix)).string(),
                                SynthCameraJson(frame.camera));
      if (!s.ok()) return s;
      ++done;
      if (progress) progress(done, total);
    }
    scene_base += (count + params.frames_per_scene - 1) / params.frames_per_scene;
  }
  return Status::Ok();
}

}  // namespace tod
