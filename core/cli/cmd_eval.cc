// tod eval --data DIR --model MODEL_DIR [--split test] [--json FILE] [--plots DIR]
#include <iostream>

#include "core/base/atomic_file.h"
#include "core/cli/commands.h"
#include "core/evaluation/evaluator.h"
#include "core/evaluation/plots.h"
#include "core/pipeline/model_bundle.h"

namespace tod::cli {

Runner AddEvalCommand(CLI::App& app) {
  struct Args {
    EvalOptions eval;
    std::string model, json, plots;
    std::string on_bad_frame = "fail";
    bool record = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("eval", "the paper's proposal and regression tables on a split");
  cmd->add_option("--data", args->eval.data_root, "dataset root")->required();
  cmd->add_option("--model", args->model, "model bundle directory")->required();
  cmd->add_option("--split", args->eval.split, "split to evaluate");
  cmd->add_option("--format", args->eval.format, "dataset format")
      ->check(CLI::IsMember({"auto", "laf", "masks", "modd2"}));
  cmd->add_option("--split-file", args->eval.split_file,
                  "masks format: `train|test <stem>` lines to use instead of DATA/split.txt");
  cmd->add_option("--max-frames", args->eval.max_frames,
                  "evaluate at most this many frames (0 = all)");
  cmd->add_option("--threads", args->eval.threads, "worker threads (0 = all cores)");
  cmd->add_option("--on-bad-frame", args->on_bad_frame,
                  "fail: stop at an unreadable frame; skip: leave it out, list and count it")
      ->check(CLI::IsMember({"fail", "skip"}));
  cmd->add_option("--json", args->json, "write the numbers as JSON to this file");
  cmd->add_option("--plots", args->plots, "draw the paper's curves as PNG into this directory");
  cmd->add_flag("--record", args->record,
                "store the numbers in the bundle's manifest.json (its own eval numbers)");
  return [args] {
    BoundOpenCvThreads(args->eval.threads);
    auto bundle = LoadModelBundle(args->model);
    if (!bundle.ok()) return Fail(bundle.status().message());
    EvalOptions options = args->eval;
    options.on_bad_frame = *ParseBadFramePolicy(args->on_bad_frame);  // checked by CLI11
    options.progress = [](const std::string& line) { std::cerr << "eval: " << line << "\n"; };
    auto report = EvaluateModel(*bundle, options);
    if (!report.ok()) return Fail(report.status().message());
    std::cout << FormatEvalTables(*report);
    if (!args->json.empty()) {
      const Status st = WriteFileAtomically(args->json, EvalReportToJson(*report).dump(2) + "\n");
      if (!st.ok()) return Fail(st.message());
    }
    if (args->record) {
      nlohmann::json numbers = EvalReportToJson(*report);
      numbers["data"] = options.data_root;
      numbers["split"] = options.split;
      const Status st = UpdateManifestEval(args->model, numbers);
      if (!st.ok()) return Fail(st.message());
    }
    if (!args->plots.empty()) {
      const Status st = WriteEvalPlots(*report, args->plots);
      if (!st.ok()) return Fail(st.message());
    }
    return 0;
  };
}

}  // namespace tod::cli
