// `tod train`: learns every part of the model from a dataset's training split - multilayer
// regions, size filter, pixel edge classifier, occlusion classifier, ORDR and OBDR, the obstacle
// score calibration - and returns the bundle (the caller saves it). Frames are streamed through
// the steps (memory does not grow with the split); a part that cannot be trained fails the run
// with a message naming the step; the manifest records what each part was trained on.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/data/pasted_obstacles.h"
#include "core/datasets/bad_frames.h"
#include "core/edges/edge_source.h"
#include "core/edges/occlusion_classifier.h"
#include "core/features/sample_selection.h"
#include "core/forest/random_forest.h"
#include "core/pipeline/model_bundle.h"
#include "core/training/training_folds.h"

namespace tod {

struct TrainOptions {
  std::string data_root;
  std::string format = "auto";  // auto | laf | masks | modd2
  std::string split = "train";
  std::string split_file;  // masks: instead of <data_root>/split.txt
  // More datasets trained on together with data_root (same split name; each its own format and
  // split file), e.g. synthetic scenes beside real frames. Frames must share one size.
  std::vector<std::string> more_data;
  std::string data_terms;        // the training data's terms of use, recorded in the manifest
  std::string regions = "auto";  // auto (k-means on the training obstacles) | laf2020
  // How the size filter's ranges come from the training obstacles: ground_plane (ours; pools
  // every obstacle through h, w, area per row below a fitted horizon, ground_plane_size_prior.h)
  // or bands (the authors' per-band min / max, §4.3).
  std::string size_filter_recipe = "ground_plane";
  // Proposal features 10, 12, 13 (PipelineParams::box_features): ground_plane (ours; column
  // offset, width and height over the rows below the ground-plane prior's horizon,
  // docs/method.md#ground-plane-box-features) or paper.
  std::string box_size_features = "ground_plane";
  // The occlusion classifier's boundary length, region areas and vertical order
  // (PipelineParams::occlusion_features): ground_plane (ours; over the rows below the same
  // horizon) or paper (pixels).
  std::string occlusion_size_features = "paper";
  std::string edge_source = "pixel_forest";  // pixel_forest | gradient | sed
  std::string sed_model;                     // model file for edge_source "sed"
  std::uint64_t seed = 1;
  int max_frames = 0;            // 0 = the whole split
  int classifier_frames = 60;    // frames used for the edge and occlusion classifiers
  int threads = 0;               // 0 = all cores
  bool prior_correction = true;  // undo the classifiers' balanced sampling (PriorCorrection)
  BadFramePolicy on_bad_frame = BadFramePolicy::kFail;
  // A new bundle's parameters: PipelineParams' own, with the occlusion classifier's early exit
  // on (TrainingDefaultParams).
  PipelineParams params = TrainingDefaultParams();
  PixelEdgeParams edge_params;
  OcclusionParams occlusion_params;
  ForestParams regressor{.num_trees = 200, .max_features = 6, .min_leaf_size = 5};
  SampleSelectionParams selection;
  // Bootstrapping (not in the paper; docs/method.md#hard-negative-mining): after a first round,
  // sample the regressors' negatives again, taking the "hard" share (selection.hard_fraction)
  // from the proposals the first round's regressors score above selection.hard_objectness
  // (fused score) instead of by objectness, and train again. false: one round, hard negatives
  // by objectness (the paper's training).
  bool mine_hard_negatives = true;
  // Pasted obstacles (not in the paper; docs/findings.md#pasted-obstacles): the regressors
  // also learn from this many copies of every training frame with obstacles of other frames of
  // its fold pasted in (0 = the frames as they are). Only the regressors' samples: the edge and
  // occlusion classifiers, the calibration and the map's fit see the real frames alone.
  int pasted_copies = 0;
  // Truth boxes as positives (not in the paper; docs/method.md#truth-box-positives): every
  // training obstacle's
  // own box, in each region that holds it, is one more positive of both regressors beside the
  // proposals that overlap it best, so the forests see what a box framing an obstacle exactly
  // looks like even where the proposal stage found none.
  // false: the paper's positives alone.
  bool truth_box_positives = true;
  PasteParams paste;
  // Stacked training (not in the paper; docs/method.md#out-of-fold-maps): the maps a learned
  // part trains on
  // (edge maps for the occlusion classifier; edge and occlusion maps for the regressors and the
  // score calibration) come from classifiers trained on the other of two folds of frames, so
  // they are as clean as a new frame's, not as a memorised one's. false: the final classifiers'
  // maps of frames they have seen (the paper's training).
  bool out_of_fold_maps = true;
  // How the frames are dealt into those folds and the calibration's (training_folds.h): runs of
  // whole drives (the default; docs/findings.md#folds-as-runs-of-consecutive-frames) or in turn.
  FoldLayout fold_layout = FoldLayout::kSequenceBlocks;
  // The probability map's isolation exponent (box_isolation.h; not in the paper): fitted on the
  // calibration's out-of-fold maps (map_isolation_fit.h). false: 0, the paper's map.
  bool fit_map_isolation = true;
  std::function<void(const std::string&)> progress;  // one line per step
};

Result<ModelBundle> TrainModel(const TrainOptions& options);

// Per-pixel labels for classifier training: 1 road (free space), 2 + i obstacle instance i,
// kIgnoreLabel (-1) void, 0 everything else.
cv::Mat1i LabelMap(const Sample& sample);

}  // namespace tod
