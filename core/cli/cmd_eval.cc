// tod eval --data DIR --model MODEL_DIR [--split test] [--geometry frame|camera|bundle]
//          [--json FILE] [--plots DIR]
#include <iostream>

#include "core/base/atomic_file.h"
#include "core/cli/commands.h"
#include "core/cli/dataset_options.h"
#include "core/cli/eval_geometry_option.h"
#include "core/evaluation/evaluator.h"
#include "core/evaluation/plots.h"
#include "core/pipeline/model_bundle.h"

namespace tod::cli {

Runner AddEvalCommand(CLI::App& app) {
  struct Args {
    DatasetArgs data = DatasetArgsOfSplit("test");
    int threads = 0;
    std::string model, json, plots;
    bool record = false;
    EvalGeometry geometry = EvalGeometry::kFrame;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("eval", "the paper's proposal and regression tables on a split");
  AddDatasetOptions(cmd, args->data, /*bad_frames=*/true);
  cmd->add_option("--model", args->model, "model bundle directory")->required();
  AddEvalGeometryOption(cmd, &args->geometry);
  cmd->add_option("--threads", args->threads, "worker threads (0 = all cores)");
  cmd->add_option("--json", args->json, "write the numbers as JSON to this file");
  cmd->add_option("--plots", args->plots, "draw the paper's curves as PNG into this directory");
  cmd->add_flag("--record", args->record,
                "store the numbers in the bundle's manifest.json (its own eval numbers)");
  return [args] {
    BoundOpenCvThreads(args->threads);
    auto bundle = LoadModelBundle(args->model);
    if (!bundle.ok()) return Fail(bundle.status().message());
    EvalOptions options;
    options.data = DatasetSelectionFrom(args->data);
    options.geometry = args->geometry;
    options.threads = args->threads;
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
      numbers["data"] = options.data.data_root;
      numbers["split"] = options.data.split;
      const Status st = UpdateManifestField(args->model, "eval", numbers);
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
