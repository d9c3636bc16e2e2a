// tod train --data DIR --out MODEL_DIR [--regions auto|laf2020] [--seed S] [--format ...]
// Trains every learned part on the train split, writes the bundle atomically, then (unless
// --no-eval) evaluates it on the test split and stores the numbers in its manifest.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <vector>

#include "core/cli/commands.h"
#include "core/evaluation/evaluator.h"
#include "core/pipeline/model_bundle.h"
#include "core/training/trainer.h"

namespace tod::cli {
namespace {

// `tod train`'s options as parsed, before they become TrainOptions.
struct TrainArgs {
  TrainOptions train;
  std::string out;
  bool no_eval = false;
  bool no_size_filter = false;
  bool refine_all = false;
  std::string eval_split = "test";
  int eval_frames = 0;
  int trees = 200;
  double negatives_scale = 1.0;
  std::string on_bad_frame = "fail";
  std::string fold_layout = "blocks";
};

// What to train on, with how many threads, and where the bundle goes.
void AddDataOptions(CLI::App* cmd, TrainArgs& args) {
  cmd->add_option("--data", args.train.data_root, "dataset root")->required();
  cmd->add_option("--out", args.out, "model bundle directory to write")->required();
  cmd->add_option("--regions", args.train.regions, "multilayer regions: auto (k-means) or laf2020")
      ->check(CLI::IsMember({"auto", "laf2020"}));
  cmd->add_option("--seed", args.train.seed, "random seed");
  cmd->add_option("--format", args.train.format, "dataset format")
      ->check(CLI::IsMember({"auto", "laf", "masks", "modd2"}));
  cmd->add_option("--split", args.train.split, "split to train on");
  cmd->add_option("--data-terms", args.train.data_terms,
                  "the training data's terms of use, recorded in the manifest");
  cmd->add_option("--add-data", args.train.more_data,
                  "another dataset to train on as well (repeatable; its format is detected, "
                  "masks use its own split.txt), e.g. synthetic scenes beside real frames");
  cmd->add_option("--split-file", args.train.split_file,
                  "masks format: `train|test <stem>` lines to use instead of DATA/split.txt");
  cmd->add_option("--edge-source", args.train.edge_source, "base edge map")
      ->check(CLI::IsMember({"pixel_forest", "gradient", "sed"}));
  cmd->add_option("--sed-model", args.train.sed_model,
                  "OpenCV StructuredEdgeDetection model (.yml.gz)");
  cmd->add_option("--max-frames", args.train.max_frames,
                  "use at most this many training frames (0 = all)");
  cmd->add_option("--classifier-frames", args.train.classifier_frames,
                  "frames for the edge and occlusion classifiers");
  cmd->add_option("--threads", args.train.threads, "worker threads (0 = all cores)");
  cmd->add_option("--on-bad-frame", args.on_bad_frame,
                  "fail: stop at an unreadable frame; skip: leave it out, list and count it")
      ->check(CLI::IsMember({"fail", "skip"}));
}

// ORDR and OBDR: their forests and the samples they learn from.
void AddRegressorOptions(CLI::App* cmd, TrainArgs& args) {
  cmd->add_option("--trees", args.trees, "trees per regressor (paper: 200)")
      ->check(CLI::Range(1, 2000));
  cmd->add_option("--regressor-mtry", args.train.regressor.max_features,
                  "features tried per split of ORDR and OBDR (Liaw-Wiener default: 6 of 20)")
      ->check(CLI::Range(1, 64));
  cmd->add_option("--regressor-min-leaf", args.train.regressor.min_leaf_size,
                  "samples a leaf of ORDR and OBDR holds at least (Liaw-Wiener default: 5)")
      ->check(CLI::Range(1, 100000));
  cmd->add_option("--negatives-scale", args.negatives_scale,
                  "regressor negatives per frame and vertical range, as a multiple of the "
                  "paper's (ORDR 17, OBDR 25)")
      ->check(CLI::Range(0.1, 20.0));
  cmd->add_option("--hard-fraction", args.train.selection.hard_fraction,
                  "share of the regressors' negatives drawn as hard ones (tau_l; paper: 0.2)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--paste-obstacles", args.train.pasted_copies,
                  "regressors: also learn from N copies of every training frame with obstacles "
                  "of other frames of its fold pasted in at their own rows, shifted sideways "
                  "(0 = the frames as they are)")
      ->check(CLI::Range(0, 8));
  cmd->add_flag("--truth-box-positives,!--no-truth-box-positives", args.train.truth_box_positives,
                "regressors: every training obstacle's own box, in each region that holds it, is "
                "one more positive beside the proposals that overlap it best (the default; "
                "--no-truth-box-positives: the paper's positives alone)");
  cmd->add_option("--negative-bags", args.train.selection.negative_bags,
                  "regressors: draw the negatives N times (disjoint draws of the paper's counts) "
                  "and fit each regressor as N forests of trees/N, each on every positive and "
                  "one draw (balanced bagging; 1 = the paper's single draw)")
      ->check(CLI::Range(1, kMaxNegativeBags));
  cmd->add_flag("--mine-hard-negatives,!--no-mine-hard-negatives", args.train.mine_hard_negatives,
                "train the regressors twice, the second time with the first round's best-scored "
                "non-obstacles as hard negatives (the default; --no-mine-hard-negatives: one "
                "round, hard negatives by objectness, as the paper)");
}

// The pixel edge and occlusion classifiers, the superpixels, and the maps they train on.
void AddClassifierOptions(CLI::App* cmd, TrainArgs& args) {
  cmd->add_option("--edge-trees", args.train.edge_params.forest.num_trees,
                  "trees of the pixel edge classifier")
      ->check(CLI::Range(1, 200));
  cmd->add_option("--edge-negatives", args.train.edge_params.negatives_per_positive,
                  "pixel edge classifier: negative cells drawn per boundary cell of a frame "
                  "(1 = balanced, ALGORITHM.md 3.4)")
      ->check(CLI::Range(0.1, 1000.0));
  cmd->add_option("--occlusion-trees", args.train.occlusion_params.forest.num_trees,
                  "trees of the occlusion classifier")
      ->check(CLI::Range(1, 2000));
  cmd->add_option("--occlusion-negatives", args.train.occlusion_params.negatives_per_positive,
                  "occlusion classifier: negative superpixel pairs kept per obstacle-contour "
                  "pair")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--occlusion-screen-trees", args.train.params.occlusion_screening.trees,
                  "occlusion classifier's early exit: a superpixel pair whose mean over its "
                  "first N trees is at most --occlusion-screen-below keeps that mean (0 = off; "
                  "default 25)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--occlusion-screen-below", args.train.params.occlusion_screening.final_at_most,
                  "the early exit's bound on the first trees' mean probability (default 0.05)")
      ->check(CLI::Range(0.0, 0.999));
  cmd->add_option("--superpixel-strips", args.train.params.superpixels.strip_rows,
                  "sweep the sticky superpixels in strips of N rows, side by side on a "
                  "request's threads (0 = raster order, one thread: the default)")
      ->check(CLI::NonNegativeNumber);
  bool* correct = &args.train.prior_correction;
  cmd->add_flag_callback(
      "--no-prior-correction", [correct] { *correct = false; },
      "keep the classifiers' balanced-sample prior (as bundles before the correction)");
  bool* out_of_fold = &args.train.out_of_fold_maps;
  cmd->add_flag_callback(
      "--in-sample-maps", [out_of_fold] { *out_of_fold = false; },
      "train each learned part on maps of the final classifiers, which have seen those frames "
      "(the paper's training; default: maps from classifiers trained on the other of two folds "
      "of frames, as a new frame's)");
  cmd->add_option("--fold-layout", args.fold_layout,
                  "how frames are dealt into the two folds of the out-of-fold maps and the score "
                  "calibration: blocks (each fold one run of consecutive frames, so a frame's "
                  "neighbours in its drive stay out of the copy that maps it; the default) or "
                  "alternate (in turn, the earlier recipe)")
      ->check(CLI::IsMember({"blocks", "alternate"}));
}

// The proposals, their features and the probability map.
void AddProposalAndMapOptions(CLI::App* cmd, TrainArgs& args) {
  cmd->add_flag("--no-size-filter", args.no_size_filter, "switch the box size filter off");
  cmd->add_option("--size-filter-recipe", args.train.size_filter_recipe,
                  "size filter ranges: ground_plane (every obstacle's size per row below a fitted "
                  "horizon, default) or bands (the authors' per-band min / max)")
      ->check(CLI::IsMember({"ground_plane", "bands"}));
  cmd->add_option("--box-size-features", args.train.box_size_features,
                  "proposal features 10, 12, 13: ground_plane (column offset, width and height "
                  "over the rows below a fitted horizon, default) or paper (over the image's size)")
      ->check(CLI::IsMember({"paper", "ground_plane"}));
  cmd->add_option("--occlusion-size-features", args.train.occlusion_size_features,
                  "occlusion classifier's boundary length, region areas and vertical order: "
                  "paper (pixels, default) or ground_plane (over the rows below a fitted horizon)")
      ->check(CLI::IsMember({"paper", "ground_plane"}));
  cmd->add_option("--refine-limit", args.train.params.boxes.refine_limit,
                  "refine at most the N best grid local maxima per region (0 = all of them)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--wide-aspect-ratio", args.train.params.boxes.max_wide_aspect_ratio,
                  "the proposal grid's widest window, w / h (ours, default 10: obstacles lying "
                  "on the road are foreshortened; 0 = tau_a, the paper's grid, 4.2 : 1 at most)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_flag("--refine-all", args.refine_all,
                "refine every scoring window, as the paper (default: the 5000 best grid local "
                "maxima per region)");
  cmd->add_flag("--fit-map-isolation,!--no-map-isolation", args.train.fit_map_isolation,
                "weight each box of the probability map by how isolated it is among the frame's "
                "best boxes, to the power fitted on the calibration's out-of-fold maps (the "
                "default; --no-map-isolation: the paper's map)");
  cmd->add_flag("--map-shares,!--no-map-shares",
                args.train.params.probability_map.superpixel_shares,
                "the probability map adds each box's score to a pixel times the share of the "
                "pixel's superpixel the box holds (the default; --no-map-shares: whole boxes, "
                "the paper's map)");
  cmd->add_flag("--vertical-edge-feature,!--no-vertical-edge-feature",
                args.train.params.vertical_edge_feature,
                "give the regressors a 21st proposal feature, the share of the box's strong "
                "gradient on near-vertical edges (the default; --no-vertical-edge-feature: the "
                "paper's 20 features)");
  cmd->add_flag("--orientation-entropy-feature,!--no-orientation-entropy-feature",
                args.train.params.orientation_entropy_feature,
                "give the regressors one more proposal feature, the orientation entropy of the "
                "box's strong gradients (--no-orientation-entropy-feature: without it)");
  cmd->add_flag("--road-surround-feature,!--no-road-surround-feature",
                args.train.params.road_surround_feature,
                "give the regressors one more proposal feature, how unlike the road just in front "
                "of the car the box's surround is (the default; --no-road-surround-feature: "
                "without it)");
}

// The evaluation that follows training.
void AddEvalOptions(CLI::App* cmd, TrainArgs& args) {
  cmd->add_flag("--no-eval", args.no_eval, "do not evaluate the new bundle on the test split");
  cmd->add_option("--eval-split", args.eval_split, "split evaluated after training");
  cmd->add_option("--eval-frames", args.eval_frames,
                  "evaluate on at most this many frames (0 = all)");
}

// The trainer's options from the parsed ones: the choices CLI11 checked, the paper's negative
// counts scaled, and the flags that switch stages off or widen them.
TrainOptions TrainOptionsFrom(const TrainArgs& args) {
  TrainOptions options = args.train;
  options.on_bad_frame = *ParseBadFramePolicy(args.on_bad_frame);  // checked by CLI11
  options.fold_layout = *ParseFoldLayout(args.fold_layout);        // checked by CLI11
  if (!options.sed_model.empty() && options.edge_source != "sed") options.edge_source = "sed";
  options.regressor.num_trees = args.trees;
  for (std::vector<int>* counts :
       {&options.selection.ordr_negatives, &options.selection.obdr_negatives}) {
    for (int& n : *counts) n = std::max(1, static_cast<int>(std::lround(n * args.negatives_scale)));
  }
  options.params.size_filter = !args.no_size_filter;
  if (args.refine_all) {
    options.params.boxes.refine_local_maxima = false;
    options.params.boxes.refine_limit = 0;
  }
  options.progress = [](const std::string& line) { std::cerr << "train: " << line << "\n"; };
  return options;
}

// Evaluates the written bundle on the eval split and stores the numbers in its manifest. A
// failed evaluation leaves the bundle as written (it is whole) and says why.
int EvaluateIntoManifest(const ModelBundle& bundle, const TrainOptions& trained,
                         const TrainArgs& args) {
  EvalOptions eval;
  eval.data_root = trained.data_root;
  eval.format = trained.format;
  eval.split_file = trained.split_file;
  eval.on_bad_frame = trained.on_bad_frame;
  eval.split = args.eval_split;
  eval.max_frames = args.eval_frames;
  eval.threads = trained.threads;
  eval.progress = [](const std::string& line) { std::cerr << "eval: " << line << "\n"; };
  auto report = EvaluateModel(bundle, eval);
  if (!report.ok()) {
    std::cerr << "tod: bundle written, evaluation skipped: " << report.status().message() << "\n";
    return 0;
  }
  std::cout << FormatEvalTables(*report);
  nlohmann::json numbers = EvalReportToJson(*report);
  numbers["split"] = eval.split;
  const Status st = UpdateManifestEval(args.out, numbers);
  return st.ok() ? 0 : Fail(st.message());
}

}  // namespace

Runner AddTrainCommand(CLI::App& app) {
  auto args = std::make_shared<TrainArgs>();
  CLI::App* cmd = app.add_subcommand("train", "train a model bundle from a dataset's train split");
  AddDataOptions(cmd, *args);
  AddRegressorOptions(cmd, *args);
  AddClassifierOptions(cmd, *args);
  AddProposalAndMapOptions(cmd, *args);
  AddEvalOptions(cmd, *args);
  return [args] {
    BoundOpenCvThreads(args->train.threads);
    const TrainOptions options = TrainOptionsFrom(*args);
    auto bundle = TrainModel(options);
    if (!bundle.ok()) return Fail(bundle.status().message());
    const Status st = SaveModelBundle(*bundle, args->out, options.sed_model);
    if (!st.ok()) return Fail(st.message());
    std::cout << "wrote model bundle " << args->out << "\n";
    return args->no_eval ? 0 : EvaluateIntoManifest(*bundle, options, *args);
  };
}

}  // namespace tod::cli
