// tod: synthesise data, train a model bundle, detect obstacles, evaluate (ALGORITHM.md).
#include <iostream>
#include <map>
#include <opencv2/core/utility.hpp>

#include "core/base/heap_tuning.h"
#include "core/cli/commands.h"

namespace tod::cli {

int Fail(const std::string& message) {
  std::cerr << "tod: " << message << "\n";
  return 1;
}

void BoundOpenCvThreads(int threads) {
  if (threads > 0) cv::setNumThreads(threads);
}

}  // namespace tod::cli

int main(int argc, char** argv) {
  tod::RetainLargeAllocations();  // detect / train / eval run the pipeline frame after frame
  CLI::App app{"tod: tiny obstacle discovery (occlusion-aware multilayer regression)"};
  app.require_subcommand(1);
  std::map<CLI::App*, tod::cli::Runner> runners;
  auto add = [&](tod::cli::Runner (*adder)(CLI::App&)) {
    const std::size_t before = app.get_subcommands({}).size();
    tod::cli::Runner run = adder(app);
    runners[app.get_subcommands({})[before]] = std::move(run);
  };
  add(tod::cli::AddSynthCommand);
  add(tod::cli::AddTrainCommand);
  add(tod::cli::AddDetectCommand);
  add(tod::cli::AddEvalCommand);
  add(tod::cli::AddAnalyseCommand);
  add(tod::cli::AddBenchCommand);
  add(tod::cli::AddCvCommand);
  add(tod::cli::AddHorizonCommand);
  add(tod::cli::AddCalibrateCommand);
  add(tod::cli::AddReframeCommand);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  for (auto& [sub, run] : runners) {
    if (!sub->parsed()) continue;
    // detect and bench run frames as the server does, with threads per request and (bench)
    // frames side by side: one heap, as tod_server has, keeps one frame's peak instead of one
    // per thread (`tod bench --threads-per-request 2` on 8 real frames: peak RSS 397-430 ->
    // 212-216 MB, the same times). Not for train / eval / analyse (heap_tuning.h). Before run():
    // no thread has started yet.
    if (sub->get_name() == "detect" || sub->get_name() == "bench") tod::ShareOneHeapArena();
    return run();
  }
  return 2;
}
