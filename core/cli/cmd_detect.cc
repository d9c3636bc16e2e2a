// tod detect --model MODEL_DIR IMAGE... --out DIR: per image STEM, STEM.json, STEM_prob.png
// (probability map, 255 = 1.0) and STEM_overlay.png; with --stages also the pictures and counts
// of the intermediate stages (core/evaluation/stage_images.h).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "core/base/atomic_file.h"
#include "core/calibration/camera_registry.h"
#include "core/cli/commands.h"
#include "core/cli/request_options.h"
#include "core/data/image_file.h"
#include "core/evaluation/stage_images.h"
#include "core/pipeline/detection_output.h"
#include "core/pipeline/frame_budget.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/pipeline/warm_up.h"

namespace tod::cli {

namespace {

struct DetectArgs {
  std::string model, out;
  std::vector<std::string> images;
  DetectOptions options;
  std::string camera_id;  // the images are frames of this camera (one horizon estimate)
  bool stages = false;
};

void AddDetectOptions(CLI::App* cmd, const std::shared_ptr<DetectArgs>& args) {
  cmd->add_option("--model", args->model, "model bundle directory")->required();
  cmd->add_option("--out", args->out, "output directory")->required();
  cmd->add_option("images", args->images, "image files (PNG, JPEG)")->required();
  cmd->add_option("--min-obstacle-score", args->options.min_obstacle_score,
                  "report only obstacles whose calibrated score reaches this")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--threshold", args->options.obstacle_threshold, "obstacle threshold on the map")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--max-proposals", args->options.max_proposals, "proposals listed in the JSON")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option_function<std::string>(
         "--map-kind",
         [args](const std::string& name) { args->options.map_kind = *ParseMapKind(name); },
         "probability map written and thresholded: normalized (the paper's, default) or "
         "calibrated")
      ->check(
          CLI::IsMember({MapKindName(MapKind::kNormalized), MapKindName(MapKind::kCalibrated)}));
  AddFrameRequestOptions(cmd, &args->options);
  cmd->add_option("--camera-id", args->camera_id,
                  "the images are frames of one camera: each frame's horizon estimate joins the "
                  "camera's, and every frame uses the camera's median so far (as the server does "
                  "for a camera_id)");
  cmd->add_flag(
      "--no-calibrate", [args](std::int64_t) { args->options.calibrate = false; },
      "use the bundle's geometry as trained instead of calibrating it to each frame's horizon");
  cmd->add_flag(
      "--stages", args->stages,
      "also write each stage as PNG (STEM_stage_*.png) and its counts (STEM_stages.json)");
}

// The frame budget counts from decoding, as in tod_server and tod bench: what the decode took
// is taken off it.
DetectOptions OptionsAfterDecode(DetectOptions options,
                                 std::chrono::steady_clock::time_point read_start) {
  if (options.budget_ms <= 0) return options;
  const double decode_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - read_start)
          .count();
  options.budget_ms = std::max(1.0, options.budget_ms - decode_ms);
  return options;
}

// STEM.json, STEM_prob.png, STEM_overlay.png and, with a trace, the stage pictures.
Status WriteDetectOutputs(const std::filesystem::path& base, const std::string& path,
                          const cv::Mat3b& image, const Detection& detection,
                          const FrameTrace* trace) {
  Status st =
      WriteFileAtomically(base.string() + ".json", DetectionToJson(detection, path).dump(2) + "\n");
  if (st.ok())
    st = WritePngAtomically(base.string() + "_prob.png", ProbabilityTo8Bit(detection.probability));
  if (st.ok())
    st = WritePngAtomically(base.string() + "_overlay.png", DrawOverlay(image, detection));
  if (!st.ok() || trace == nullptr) return st;
  auto stages = RenderStageImages(*trace, image);
  if (!stages.ok()) return stages.status();
  stages->counts["image"] = path;
  return WriteStageImages(*stages, base.string());
}

// One image file. A frame that cannot be read or detected is reported and counted in
// `failures` (the run goes on with the next); a failed write ends the run.
Status DetectFile(const ObstacleDetector& detector, const DetectArgs& args, const std::string& path,
                  int& failures) {
  const auto read_start = std::chrono::steady_clock::now();
  // Decoded as tod_server and tod bench decode (plain PNGs without libpng).
  const Result<cv::Mat> read = ReadImageFile(path, cv::IMREAD_COLOR, "image");
  if (!read.ok()) {
    std::cerr << "tod: " << path << ": not a readable image (" << read.status().message() << ")\n";
    ++failures;
    return Status::Ok();
  }
  const cv::Mat& image = *read;
  // With --stages the detection's own trace is drawn: the stages run once.
  FrameTrace trace;
  FrameTrace* const traced = args.stages ? &trace : nullptr;
  auto detection = detector.Detect(image, OptionsAfterDecode(args.options, read_start), traced);
  if (!detection.ok()) {
    std::cerr << "tod: " << path << ": " << detection.status().message() << "\n";
    ++failures;
    return Status::Ok();
  }
  const std::string stem = std::filesystem::path(path).stem().string();
  const std::filesystem::path base = std::filesystem::path(args.out) / stem;
  if (Status st = WriteDetectOutputs(base, path, image, *detection, traced); !st.ok()) return st;
  double total = 0;
  for (const auto& [stage, ms] : detection->timings) total += ms;
  std::cout << path << ": " << detection->obstacles.size() << " obstacles, "
            << detection->proposals.size() << " proposals listed, " << static_cast<int>(total)
            << " ms -> " << base.string() << "{.json,_prob.png,_overlay.png"
            << (args.stages ? ",_stage_*.png,_stages.json" : "") << "}\n";
  return Status::Ok();
}

}  // namespace

Runner AddDetectCommand(CLI::App& app) {
  auto args = std::make_shared<DetectArgs>();
  AddDetectOptions(app.add_subcommand("detect", "find obstacles in images"), args);
  return [args] {
    UseRequestThreadsForOpenCv(args->options);
    auto loaded = Detector::Load(args->model);
    if (!loaded.ok()) return Fail(loaded.status().message());
    // The stage pictures need the detector's trace, which only the bundle's own detector keeps.
    const auto detector = std::dynamic_pointer_cast<const ObstacleDetector>(*loaded);
    if (detector == nullptr) return Fail(args->model + ": not an obstacle detector bundle");
    if (!args->camera_id.empty()) {
      if (Status st = CheckCameraId(args->camera_id, CameraRegistryParams{}); !st.ok())
        return Fail("--camera-id: " + st.message());
      args->options.camera = std::make_shared<CameraTrack>();
    }
    // One-off costs of the process (warm_up.h) are paid here, not by the first frame's budget.
    if (const Result<double> warmed = WarmUp(*detector); !warmed.ok())
      return Fail(warmed.status().message());
    std::error_code ec;
    std::filesystem::create_directories(args->out, ec);
    if (ec) return Fail("cannot create " + args->out + ": " + ec.message());
    int failures = 0;
    for (const std::string& path : args->images) {
      const Status st = DetectFile(*detector, *args, path, failures);
      if (!st.ok()) return Fail(st.message());
    }
    return failures == 0 ? 0 : 1;
  };
}

}  // namespace tod::cli
