// tod detect --model MODEL_DIR IMAGE... --out DIR: per image STEM, STEM.json, STEM_prob.png
// (probability map, 255 = 1.0) and STEM_overlay.png.
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "core/base/atomic_file.h"
#include "core/cli/commands.h"
#include "core/pipeline/detection_output.h"

namespace tod::cli {
namespace {

Status WritePng(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes)) return Status::Internal("cannot encode " + path);
  return WriteFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace

Runner AddDetectCommand(CLI::App& app) {
  struct Args {
    std::string model, out;
    std::vector<std::string> images;
    DetectOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("detect", "find obstacles in images");
  cmd->add_option("--model", args->model, "model bundle directory")->required();
  cmd->add_option("--out", args->out, "output directory")->required();
  cmd->add_option("images", args->images, "image files (PNG, JPEG)")->required();
  cmd->add_option("--threshold", args->options.obstacle_threshold, "obstacle threshold on the map")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--max-proposals", args->options.max_proposals, "proposals listed in the JSON")
      ->check(CLI::NonNegativeNumber);
  return [args] {
    auto detector = Detector::Load(args->model);
    if (!detector.ok()) return Fail(detector.status().message());
    std::error_code ec;
    std::filesystem::create_directories(args->out, ec);
    if (ec) return Fail("cannot create " + args->out + ": " + ec.message());
    int failures = 0;
    for (const std::string& path : args->images) {
      const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
      if (image.empty()) {
        std::cerr << "tod: " << path << ": not a readable image\n";
        ++failures;
        continue;
      }
      auto detection = (*detector)->Detect(image, args->options);
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
        st = WritePng(base.string() + "_prob.png", ProbabilityTo8Bit(detection->probability));
      if (st.ok()) st = WritePng(base.string() + "_overlay.png", DrawOverlay(image, *detection));
      if (!st.ok()) return Fail(st.message());
      double total = 0;
      for (const auto& [stage, ms] : detection->timings) total += ms;
      std::cout << path << ": " << detection->obstacles.size() << " obstacles, "
                << detection->proposals.size() << " proposals listed, " << static_cast<int>(total)
                << " ms -> " << base.string() << "{.json,_prob.png,_overlay.png}\n";
    }
    return failures == 0 ? 0 : 1;
  };
}

}  // namespace tod::cli
