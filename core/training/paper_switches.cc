#include "core/training/paper_switches.h"

namespace tod {

std::string_view PaperSwitchHelp(PaperSwitch which) {
  switch (which) {
    case PaperSwitch::kPriorCorrection:
      return "keep the classifiers' balanced-sample prior";
    case PaperSwitch::kSizeFilter:
      return "size filter ranges from the authors' per-band min / max, not the ground plane";
    case PaperSwitch::kLocalMaximaRefinement:
      return "refine every scoring window, not the 5000 best grid local maxima per region";
    case PaperSwitch::kWideWindows:
      return "the paper's window grid (w / h at most 4.2), without the wide shapes";
    case PaperSwitch::kOutOfFoldMaps:
      return "train each part on the final classifiers' maps of frames they have seen";
    case PaperSwitch::kHardNegativeMining:
      return "one round of the regressors, hard negatives by objectness";
    case PaperSwitch::kTruthBoxPositives:
      return "the regressors' positives from the proposals alone";
    case PaperSwitch::kBoxSizeFeatures:
      return "proposal features 10, 12, 13 over the image's size, not the ground plane";
    case PaperSwitch::kVerticalEdgeFeature:
      return "without proposal feature 21, the vertical edge share";
    case PaperSwitch::kRoadSurroundFeature:
      return "without proposal feature 22, the surround unlike the road";
    case PaperSwitch::kMapIsolation:
      return "the probability map without the fitted isolation weight";
    case PaperSwitch::kSuperpixelShares:
      return "the probability map adds whole boxes, not superpixel shares";
    case PaperSwitch::kOcclusionEarlyExit:
      return "every occlusion tree on every superpixel pair (no early exit)";
  }
  return "";
}

void ApplyPaperSwitch(PaperSwitch which, TrainOptions& options) {
  PipelineParams& params = options.params;
  switch (which) {
    case PaperSwitch::kPriorCorrection:
      options.prior_correction = false;
      return;
    case PaperSwitch::kSizeFilter:
      options.size_filter_recipe = SizeFilterRecipe::kBands;
      return;
    case PaperSwitch::kLocalMaximaRefinement:
      params.boxes.refine_local_maxima = false;
      params.boxes.refine_limit = 0;
      return;
    case PaperSwitch::kWideWindows:
      params.boxes.max_wide_aspect_ratio = 0.f;
      return;
    case PaperSwitch::kOutOfFoldMaps:
      options.out_of_fold_maps = false;
      return;
    case PaperSwitch::kHardNegativeMining:
      options.mine_hard_negatives = false;
      return;
    case PaperSwitch::kTruthBoxPositives:
      options.truth_box_positives = false;
      return;
    case PaperSwitch::kBoxSizeFeatures:
      options.box_size_features = BoxSizeFeatures::kPaper;
      return;
    case PaperSwitch::kVerticalEdgeFeature:
      params.vertical_edge_feature = false;
      return;
    case PaperSwitch::kRoadSurroundFeature:
      params.road_surround_feature = false;
      return;
    case PaperSwitch::kMapIsolation:
      options.fit_map_isolation = false;
      return;
    case PaperSwitch::kSuperpixelShares:
      params.probability_map.superpixel_shares = false;
      return;
    case PaperSwitch::kOcclusionEarlyExit:
      // No trees screened: every pair walks the whole forest. The bound stays as recorded, so
      // the manifest reads as `--occlusion-screen-trees 0` wrote it.
      params.occlusion_screening.trees = 0;
      return;
  }
}

std::string PaperSwitchesHelp() {
  std::string lines;
  for (const auto& [which, name] : EnumNames<PaperSwitch>::kTable)
    lines += "\n  " + std::string(name) + ": " + std::string(PaperSwitchHelp(which));
  return lines;
}

}  // namespace tod
