// The switches back to the paper, one per adopted deviation (docs/method.md#deviations-from-the-
// paper): `tod train --paper NAME` (repeatable) trains that part as the paper does, for the
// ablation table. Every name, its help line and what it changes are here and nowhere else.
#pragma once

#include <string>
#include <string_view>

#include "core/base/enum_names.h"
#include "core/training/train_options.h"

namespace tod {

enum class PaperSwitch {
  kPriorCorrection,
  kSizeFilter,
  kLocalMaximaRefinement,
  kWideWindows,
  kOutOfFoldMaps,
  kHardNegativeMining,
  kTruthBoxPositives,
  kBoxSizeFeatures,
  kVerticalEdgeFeature,
  kRoadSurroundFeature,
  kMapIsolation,
  kSuperpixelShares,
  kOcclusionEarlyExit,
};

template <>
struct EnumNames<PaperSwitch> {
  static constexpr std::array<std::pair<PaperSwitch, std::string_view>, 13> kTable{{
      {PaperSwitch::kPriorCorrection, "prior_correction"},
      {PaperSwitch::kSizeFilter, "size_filter"},
      {PaperSwitch::kLocalMaximaRefinement, "local_maxima_refinement"},
      {PaperSwitch::kWideWindows, "wide_windows"},
      {PaperSwitch::kOutOfFoldMaps, "out_of_fold_maps"},
      {PaperSwitch::kHardNegativeMining, "hard_negative_mining"},
      {PaperSwitch::kTruthBoxPositives, "truth_box_positives"},
      {PaperSwitch::kBoxSizeFeatures, "box_size_features"},
      {PaperSwitch::kVerticalEdgeFeature, "vertical_edge_feature"},
      {PaperSwitch::kRoadSurroundFeature, "road_surround_feature"},
      {PaperSwitch::kMapIsolation, "map_isolation"},
      {PaperSwitch::kSuperpixelShares, "superpixel_shares"},
      {PaperSwitch::kOcclusionEarlyExit, "occlusion_early_exit"},
  }};
};

// What the paper does instead, in one line.
std::string_view PaperSwitchHelp(PaperSwitch which);

// `options` with that part trained as the paper does.
void ApplyPaperSwitch(PaperSwitch which, TrainOptions& options);

// Every switch, one line each ("name: help"), for `tod train --help`.
std::string PaperSwitchesHelp();

}  // namespace tod
