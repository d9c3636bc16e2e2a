// Cross-validation of a training recipe: K folds of consecutive frames, each trained on the
// other K-1 and evaluated on itself, under N forest seeds; every number of `tod eval` per fold
// and its mean with the spread (min-max) over the folds. The way this project chooses between
// recipes (docs/results.md#cross-validation): a change is adopted only when it wins by more
// than the spread.
//
// Folds are runs of the frame numbers, never interleaved: consecutive frames of a set such as
// fs-laf-dev are often frames of one drive, and a fold that tests on the neighbours of its
// training frames tests on near-copies.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/evaluation/evaluator.h"
#include "core/training/trainer.h"

namespace tod {

struct CrossValidationOptions {
  int folds = 5;  // K
  int seeds = 1;  // N: seeds recipe.seed, recipe.seed + 1, ...
  // Where each fold's split file (and, with keep_models, its bundle) is written.
  std::string work_dir;
  bool keep_models = false;
  // Evaluate the bundles an earlier keep_models run left under work_dir instead of training:
  // detection options and evaluation changes measured on the same models in minutes. A fold's
  // bundle is refused unless the split file kept beside it is this fold's and its manifest
  // names this data and seed.
  bool reuse_models = false;
  // The held-out fold's frames are read from this dataset root instead of the training data's:
  // the same frames (same names, same layout) made into another camera (tod reframe), tested
  // with bundles trained on the originals. Empty: the training data.
  std::string test_data;
  std::function<void(const std::string&)> progress;
};

// The frames of one fold: a run of consecutive frames, by their numbers.
struct CvFold {
  std::vector<std::string> stems;  // in frame order
};

// `stems` (frame names) in frame order (numeric names by number, the others after them by
// name), dealt into `folds` runs of consecutive frames whose sizes differ by at most one.
// Fails when there are fewer frames than folds or fewer than two folds.
Result<std::vector<CvFold>> ConsecutiveFolds(std::vector<std::string> stems, int folds);

struct CrossValidationReport {
  int seeds = 1;
  std::uint64_t first_seed = 0;
  std::vector<CvFold> folds;
  // runs[k][s]: EvalReportToJson of fold k's test frames, trained with seed first_seed + s.
  std::vector<std::vector<nlohmann::json>> runs;
};

// Trains `recipe` on each fold's complement and evaluates on the fold (`eval` says how; its
// data root, format and split file are the recipe's). The data must be in the masks layout
// (images/ + labels_masks/): the folds are written as its split files.
Result<CrossValidationReport> CrossValidate(const TrainOptions& recipe, const EvalOptions& eval,
                                            const CrossValidationOptions& options);

// Every number of one `tod eval` JSON by its path ("regression/BP+Fusion@4/ap"); null (an
// undefined metric), text and flags are left out.
std::map<std::string, double> FlattenMetrics(const nlohmann::json& eval);

// {"folds","seeds","first_seed","fold_frames":[[first,last],...],"per_fold":[{path:x}],
//  "mean":{path:x},"min":{path:x},"max":{path:x},"runs":[[eval json per seed]]}: per_fold
// averages a fold's seeds; mean, min and max are over the folds' averages, each over the folds
// where the metric is defined.
nlohmann::json CrossValidationToJson(const CrossValidationReport& report);

// The headline metrics, one row each: every fold, the mean and the min-max spread.
std::string FormatCrossValidation(const CrossValidationReport& report);

}  // namespace tod
