// What `tod train` is asked to do (trainer.h trains it). Its own header, so that the trainer's
// steps (training_run.h and the rest) and its entry point need not include each other.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/base/enum_names.h"
#include "core/datasets/dataset_selection.h"
#include "core/edges/edge_source.h"
#include "core/edges/occlusion_classifier.h"
#include "core/pipeline/pipeline_params.h"

namespace tod {

// Where the multilayer regions come from: k-means on the training obstacles (auto) or the
// authors' shipped LAF boxes (laf2020, with their size filter).
enum class RegionsSource { kAuto, kLaf2020 };
template <>
struct EnumNames<RegionsSource> {
  static constexpr std::array<std::pair<RegionsSource, std::string_view>, 2> kTable{{
      {RegionsSource::kAuto, "auto"},
      {RegionsSource::kLaf2020, "laf2020"},
  }};
};

// How the size filter's ranges come from the training obstacles: the ground-plane prior (ours;
// every obstacle's h, w, area per row below a fitted horizon, ground_plane_size_prior.h,
// docs/method.md#size-filter) or the authors' per-band min / max (bands, §4.3).
enum class SizeFilterRecipe { kGroundPlane, kBands };
template <>
struct EnumNames<SizeFilterRecipe> {
  static constexpr std::array<std::pair<SizeFilterRecipe, std::string_view>, 2> kTable{{
      {SizeFilterRecipe::kGroundPlane, "ground_plane"},
      {SizeFilterRecipe::kBands, "bands"},
  }};
};

// Proposal features 10, 12, 13 (PipelineParams::box_features): column offset, width and height
// over the rows below the ground-plane prior's horizon (ours,
// docs/method.md#ground-plane-box-features) or over the image's size (paper).
enum class BoxSizeFeatures { kGroundPlane, kPaper };
template <>
struct EnumNames<BoxSizeFeatures> {
  static constexpr std::array<std::pair<BoxSizeFeatures, std::string_view>, 2> kTable{{
      {BoxSizeFeatures::kGroundPlane, "ground_plane"},
      {BoxSizeFeatures::kPaper, "paper"},
  }};
};

struct TrainOptions {
  DatasetSelection data = SelectionOfSplit("train");
  // More datasets trained on together with data (same split name; each its own format and
  // split file), e.g. synthetic scenes beside real frames. Frames must share one size.
  std::vector<std::string> more_data;
  std::string data_terms;  // the training data's terms of use, recorded in the manifest
  RegionsSource regions = RegionsSource::kAuto;
  SizeFilterRecipe size_filter_recipe = SizeFilterRecipe::kGroundPlane;
  BoxSizeFeatures box_size_features = BoxSizeFeatures::kGroundPlane;
  EdgeKind edge_source = EdgeKind::kPixelForest;
  std::string sed_model;  // model file for EdgeKind::kSed
  std::uint64_t seed = 1;
  int classifier_frames = 60;    // frames used for the edge and occlusion classifiers
  int threads = 0;               // 0 = all cores
  bool prior_correction = true;  // undo the classifiers' balanced sampling (PriorCorrection)
  // A new bundle's parameters: PipelineParams' own, with the adopted deviations that live there
  // switched on (TrainingDefaultParams).
  PipelineParams params = TrainingDefaultParams();
  // The classifiers' parameters; `tod train` sets only their trees (the sampling ratios stay the
  // paper's: other ones were measured and removed, docs/findings.md#edge-and-occlusion-negatives).
  PixelEdgeParams edge_params;
  OcclusionParams occlusion_params;
  int regressor_trees = 200;  // trees of ORDR and of OBDR (paper: 200)
  // Bootstrapping (not in the paper; docs/method.md#hard-negative-mining): after a first round,
  // sample the regressors' negatives again, taking the "hard" share from the proposals the first
  // round's regressors score above tau_o (fused score) instead of by objectness, and train again.
  // false: one round, hard negatives by objectness (the paper's training).
  bool mine_hard_negatives = true;
  // Truth boxes as positives (not in the paper; docs/method.md#truth-box-positives): every
  // training obstacle's own box, in each region that holds it, is one more positive of both
  // regressors beside the proposals that overlap it best, so the forests see what a box framing
  // an obstacle exactly looks like even where the proposal stage found none. false: the paper's
  // positives alone.
  bool truth_box_positives = true;
  // Stacked training (not in the paper; docs/method.md#out-of-fold-maps): the maps a learned part
  // trains on (edge maps for the occlusion classifier; edge and occlusion maps for the regressors
  // and the score calibration) come from classifiers trained on the other of two folds of frames
  // (runs of whole drives, training_folds.h), so they are as clean as a new frame's, not as a
  // memorised one's. false: the final classifiers' maps of frames they have seen (the paper's).
  bool out_of_fold_maps = true;
  // The probability map's isolation exponent (box_isolation.h; not in the paper): fitted on the
  // calibration's out-of-fold maps (map_isolation_fit.h). false: 0, the paper's map.
  bool fit_map_isolation = true;
  std::function<void(const std::string&)> progress;  // one line per step
};

}  // namespace tod
