// tod bench --frames DIR [--model M] [--limit N] [--threads T] [--json FILE]: the real
// detector's time per stage over every frame under DIR, with OpenCV Edge Boxes beside it
// (core/pipeline/frame_bench.h). A benchmark, not a test: it prints tables.
#include <iostream>

#include "core/base/atomic_file.h"
#include "core/base/heap_tuning.h"
#include "core/cli/commands.h"
#include "core/cli/request_options.h"
#include "core/evaluation/frame_bench.h"
#include "core/pipeline/model_bundle.h"
#include "core/pipeline/obstacle_detector.h"

namespace tod::cli {

Runner AddBenchCommand(CLI::App& app) {
  struct Args {
    std::string frames, model = "models/default", json;
    int limit = 0;
    int threads = 1;
    DetectOptions detect;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "time every stage of the detector on a directory of frames (PNG, JPEG, WebP)");
  cmd->add_option("--frames", args->frames, "directory, searched recursively")->required();
  cmd->add_option("--model", args->model, "model bundle directory")->capture_default_str();
  cmd->add_option("--limit", args->limit, "first N frames by path (0 = all)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--threads", args->threads,
                  "frames measured in parallel (1 = one core, one frame at a time)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--json", args->json, "also write the numbers and every frame's record here");
  AddFrameRequestOptions(cmd, &args->detect);
  return [args] {
    UseRequestThreadsForOpenCv(args->detect);
    auto frames = ListBenchFrames(args->frames);
    if (!frames.ok()) return Fail(frames.status().message());
    if (frames->empty()) return Fail("no PNG, JPEG or WebP frame under " + args->frames);
    if (args->limit > 0 && static_cast<std::size_t>(args->limit) < frames->size())
      frames->resize(static_cast<std::size_t>(args->limit));
    // The concrete detector, not the Detector interface: the counting pass needs its bundle.
    auto bundle = LoadModelBundle(args->model);
    if (!bundle.ok()) return Fail(bundle.status().message());
    const ObstacleDetector detector(std::move(*bundle), args->model);

    BenchOptions options;
    options.threads = args->threads;
    options.detect = args->detect;
    options.progress = [](const std::string& line) { std::cerr << line << "\n"; };
    std::cerr << "measuring " << frames->size() << " frames (after one warm-up)\n";
    auto report = RunFrameBench(detector, *frames, options);
    if (!report.ok()) return Fail(report.status().message());
    report->shared_heap = HeapArenaShared();
    std::cout << FormatBenchReport(*report);
    if (!args->json.empty()) {
      const Status written =
          WriteFileAtomically(args->json, BenchReportToJson(*report).dump(2) + "\n");
      if (!written.ok()) return Fail(written.message());
    }
    return 0;
  };
}

}  // namespace tod::cli
