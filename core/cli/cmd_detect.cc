// tod detect --model MODEL_DIR IMAGE... --out DIR: per image STEM, STEM.json, STEM_prob.png
// (probability map, 255 = 1.0) and STEM_overlay.png; with --stages also the pictures and counts
// of the intermediate stages (core/pipeline/stage_images.h).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "core/base/atomic_file.h"
#include "core/cli/commands.h"
#include "core/cli/request_options.h"
#include "core/data/image_file.h"
#include "core/pipeline/detection_output.h"
#include "core/pipeline/frame_budget.h"
#include "core/pipeline/model_bundle.h"
#include "core/pipeline/stage_images.h"
#include "core/pipeline/warm_up.h"

namespace tod::cli {

Runner AddDetectCommand(CLI::App& app) {
  struct Args {
    std::string model, out;
    std::vector<std::string> images;
    DetectOptions options;
    bool stages = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("detect", "find obstacles in images");
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
  cmd->add_flag(
      "--stages", args->stages,
      "also write each stage as PNG (STEM_stage_*.png) and its counts (STEM_stages.json)");
  return [args] {
    UseRequestThreadsForOpenCv(args->options);
    auto detector = Detector::Load(args->model);
    if (!detector.ok()) return Fail(detector.status().message());
    // One-off costs of the process (warm_up.h) are paid here, not by the first frame's budget.
    if (const Result<double> warmed = WarmUp(**detector); !warmed.ok())
      return Fail(warmed.status().message());
    // The Detector interface hides its bundle, so the stage pictures get their own copy of the
    // same bundle (loaded only with --stages).
    std::optional<ModelBundle> stage_bundle;
    if (args->stages) {
      auto bundle = LoadModelBundle(args->model);
      if (!bundle.ok()) return Fail(bundle.status().message());
      stage_bundle = std::move(*bundle);
    }
    std::error_code ec;
    std::filesystem::create_directories(args->out, ec);
    if (ec) return Fail("cannot create " + args->out + ": " + ec.message());
    int failures = 0;
    for (const std::string& path : args->images) {
      const auto read_start = std::chrono::steady_clock::now();
      // Decoded as tod_server and tod bench decode (plain PNGs without libpng).
      const Result<cv::Mat> read = ReadImageFile(path, cv::IMREAD_COLOR, "image");
      if (!read.ok()) {
        std::cerr << "tod: " << path << ": not a readable image (" << read.status().message()
                  << ")\n";
        ++failures;
        continue;
      }
      const cv::Mat& image = *read;
      // The frame budget counts from decoding, as in tod_server and tod bench.
      DetectOptions options = args->options;
      if (options.budget_ms > 0) {
        const double decode_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - read_start)
                .count();
        options.budget_ms = std::max(1.0, options.budget_ms - decode_ms);
      }
      auto detection = (*detector)->Detect(image, options);
      if (!detection.ok()) {
        std::cerr << "tod: " << path << ": " << detection.status().message() << "\n";
        ++failures;
        continue;
      }
      const std::string stem = std::filesystem::path(path).stem().string();
      const std::filesystem::path base = std::filesystem::path(args->out) / stem;
      Status st = WriteFileAtomically(base.string() + ".json",
                                      DetectionToJson(*detection, path).dump(2) + "\n");
      if (st.ok())
        st = WritePngAtomically(base.string() + "_prob.png",
                                ProbabilityTo8Bit(detection->probability));
      if (st.ok())
        st = WritePngAtomically(base.string() + "_overlay.png", DrawOverlay(image, *detection));
      if (st.ok() && stage_bundle) {
        auto stages = RenderStageImages(*stage_bundle, image);
        if (stages.ok()) stages->counts["image"] = path;
        st = stages.ok() ? WriteStageImages(*stages, base.string()) : stages.status();
      }
      if (!st.ok()) return Fail(st.message());
      double total = 0;
      for (const auto& [stage, ms] : detection->timings) total += ms;
      std::cout << path << ": " << detection->obstacles.size() << " obstacles, "
                << detection->proposals.size() << " proposals listed, " << static_cast<int>(total)
                << " ms -> " << base.string() << "{.json,_prob.png,_overlay.png"
                << (stage_bundle ? ",_stage_*.png,_stages.json" : "") << "}\n";
    }
    return failures == 0 ? 0 : 1;
  };
}

}  // namespace tod::cli
