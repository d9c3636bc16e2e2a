// tod analyse --data DIR --model MODEL_DIR [--split test] [--json FILE]
// Where the obstacles of an annotated split are lost: edge maps, proposals, size filter, ranking.
#include <iostream>

#include "core/base/atomic_file.h"
#include "core/cli/commands.h"
#include "core/cli/dataset_options.h"
#include "core/evaluation/loss_analysis.h"
#include "core/pipeline/model_bundle.h"

namespace tod::cli {

Runner AddAnalyseCommand(CLI::App& app) {
  struct Args {
    DatasetArgs data = DatasetArgsOfSplit("test");
    LossAnalysisOptions analysis;
    std::string model, json;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "analyse", "where the obstacles of a split are lost: edges, proposals, filter, ranking");
  AddDatasetOptions(cmd, args->data, /*bad_frames=*/false);
  cmd->add_option("--model", args->model, "model bundle directory")->required();
  cmd->add_option("--threads", args->analysis.threads, "worker threads (0 = all cores)");
  cmd->add_option("--json", args->json, "write every obstacle's fate and frame's counts here");
  return [args] {
    BoundOpenCvThreads(args->analysis.threads);
    auto bundle = LoadModelBundle(args->model);
    if (!bundle.ok()) return Fail(bundle.status().message());
    LossAnalysisOptions options = args->analysis;
    options.data = DatasetSelectionFrom(args->data);
    options.progress = [](const std::string& line) { std::cerr << "analyse: " << line << "\n"; };
    auto analysis = AnalyseLosses(*bundle, options);
    if (!analysis.ok()) return Fail(analysis.status().message());
    std::cout << FormatLossAnalysis(*analysis, options);
    if (!args->json.empty()) {
      const Status st =
          WriteFileAtomically(args->json, LossAnalysisToJson(*analysis).dump(1) + "\n");
      if (!st.ok()) return Fail(st.message());
    }
    return 0;
  };
}

}  // namespace tod::cli
