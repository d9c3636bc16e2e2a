// tod cv --data DIR --work DIR [--folds 5] [--seeds 1] [--seed S] [--paper NAME] [--json FILE]
//        [--keep-models | --reuse-models] [--test-data DIR] [--geometry frame|camera|bundle]
// Cross-validates the training recipe (tod train's defaults) over K folds of consecutive frames
// and N seeds (core/validation/cross_validation.h): trains on K-1 folds, evaluates on the one
// left out, and prints the headline metrics per fold with their mean and min-max spread; the
// JSON holds every number of `tod eval` per fold and run under "cv".
#include <iostream>

#include "core/base/atomic_file.h"
#include "core/cli/commands.h"
#include "core/cli/eval_geometry_option.h"
#include "core/cli/paper_option.h"
#include "core/validation/cross_validation.h"

namespace tod::cli {

Runner AddCvCommand(CLI::App& app) {
  struct Args {
    TrainOptions recipe;
    EvalOptions eval;
    CrossValidationOptions cv;
    std::string json;
    std::vector<std::string> paper;
    int trees = 200;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "cv", "cross-validate the training recipe over folds of consecutive frames and seeds");
  cmd->add_option("--data", args->recipe.data.data_root, "dataset root (masks layout)")->required();
  cmd->add_option("--work", args->cv.work_dir,
                  "directory for the folds' split files (and, with --keep-models, bundles)")
      ->required();
  cmd->add_option("--split-file", args->recipe.data.split_file,
                  "`train|test <stem>` lines: cross-validate over the frames it lists");
  cmd->add_option("--folds", args->cv.folds, "K: folds of consecutive frames")
      ->check(CLI::Range(2, 100))
      ->capture_default_str();
  cmd->add_option("--seeds", args->cv.seeds, "N: forest seeds per fold, from --seed on")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--seed", args->recipe.seed, "first seed")->capture_default_str();
  cmd->add_option("--trees", args->trees, "trees per regressor (paper: 200)")
      ->check(CLI::Range(1, 2000))
      ->capture_default_str();
  cmd->add_option("--classifier-frames", args->recipe.classifier_frames,
                  "frames the edge and occlusion classifiers learn from (fewer: faster)")
      ->capture_default_str();
  AddPaperOption(cmd, args->paper);
  cmd->add_option("--threads", args->recipe.threads, "worker threads (0 = all cores)");
  cmd->add_flag("--keep-models", args->cv.keep_models, "keep every fold's bundle under --work");
  cmd->add_flag("--reuse-models", args->cv.reuse_models,
                "evaluate the bundles --keep-models left under --work instead of training "
                "(the same models under other detection options or evaluation code)")
      ->excludes("--keep-models");
  cmd->add_option("--test-data", args->cv.test_data,
                  "read each held-out fold's frames from this dataset root instead: the same "
                  "frames made into another camera (tod reframe)");
  AddEvalGeometryOption(cmd, &args->eval.geometry);
  cmd->add_option("--json", args->json, "write every number under \"cv\" to this file");
  return [args] {
    BoundOpenCvThreads(args->recipe.threads);
    TrainOptions recipe = args->recipe;
    recipe.regressor_trees = args->trees;
    ApplyPaperSwitches(args->paper, recipe);
    recipe.progress = [](const std::string& line) { std::cerr << "train: " << line << "\n"; };
    EvalOptions eval = args->eval;
    eval.threads = recipe.threads;
    eval.progress = [](const std::string& line) { std::cerr << "eval: " << line << "\n"; };
    CrossValidationOptions cv = args->cv;
    cv.progress = [](const std::string& line) { std::cerr << "cv: " << line << "\n"; };
    auto report = CrossValidate(recipe, eval, cv);
    if (!report.ok()) return Fail(report.status().message());
    std::cout << FormatCrossValidation(*report);
    if (!args->json.empty()) {
      const nlohmann::json out = {{"cv", CrossValidationToJson(*report)}};
      const Status st = WriteFileAtomically(args->json, out.dump(2) + "\n");
      if (!st.ok()) return Fail(st.message());
    }
    return 0;
  };
}

}  // namespace tod::cli
