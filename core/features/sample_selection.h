// Training-sample selection for the two regressors (ALGORITHM.md §6.1, §6.2, §6.4, categories
// of §4.3). Per training image: the full test-time proposal set B^I is split by the bottom edge
// of each box into vertical ranges V_k; per range, negatives are drawn at random (a fraction
// tau_l of them "hard", i.e. with objectness > tau_o); positives are the top-IoU proposals of
// each GT obstacle. ORDR negatives come from road proposals, OBDR negatives from background.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/features/mask_iou.h"

namespace tod {

struct SampleSelectionParams {
  std::vector<int> ordr_negatives{17, 17, 17, 17};  // n^-_k for ORDR, one per range [P]
  std::vector<int> obdr_negatives{25, 25, 25, 25};  // n^-_k for OBDR [P]
  std::vector<int> positives{17, 17, 17, 17};       // n^+_k, shared by both regressors [P]
  double hard_fraction = 0.2;    // tau_l: share of negatives drawn with objectness > tau_o [P]
  double hard_objectness = 0.3;  // tau_o [P]
  double obstacle_iou = 0.5;     // category (ii) when max mask IoU >= this; negatives need less
  double road_fraction = 0.5;    // category (i) when the road share of the box exceeds this
  bool box_iou_target = false;   // targets = max box-vs-box IoU instead of mask IoU (§6.4 flag)
};

enum class ProposalCategory { kRoad, kObstacle, kBackground };

// The category of §4.3 [R]: obstacle if max mask IoU >= obstacle_iou; else road if more than
// road_fraction of the box's scored pixels (its w·h pixels less the void ones, `void_pixels`)
// are road; else background. Void is neither road nor background (§3.4): counted as "not road"
// it made every box over the void ground beside a road (Fishyscapes' 255) a background box, which
// sets without a road label never draw as negatives. A box with no scored pixel is background.
ProposalCategory CategorizeProposal(const Box& box, const MaskIoUTable& obstacles,
                                    const MaskPixelCounter& road,
                                    const MaskPixelCounter& void_pixels,
                                    const SampleSelectionParams& params);

// Index k (0-based, 0 = V_1 = nearest, bottom of the image) of the vertical range containing
// `row`, given the K+1 limits y_1 > y_2 > ... > y_{K+1} (0-based rows): V_k = (y_{k+1}, y_k] for
// k < K and V_K = [y_{K+1}, y_K]. Rows below y_1 go to V_1, rows above y_{K+1} to V_K (§6.1 [R]).
// Requires at least two strictly decreasing limits (checked by SelectTrainingSamples).
int VerticalRangeIndex(int row, const std::vector<int>& range_limits);

// The row a box's "bottom edge" refers to: its last row, box.y + box.h - 1.
inline int BottomRow(const Box& box) { return box.y + box.h - 1; }

struct SelectedSamples {
  // Indices into the proposal list and their regression targets, positives first.
  std::vector<int> ordr_indices;
  std::vector<float> ordr_targets;
  std::vector<int> obdr_indices;
  std::vector<float> obdr_targets;
  std::vector<int> positive_indices;  // the shared positives (prefix of both lists above)
};

// proposals: B^I of one training image in full-image coordinates with objectness scores.
// gt: the image's annotation (road mask and obstacle instances; the road mask must be non-empty).
// range_limits: the K+1 row limits y_1 > ... > y_{K+1}; every per-range vector of `params` must
// have K entries. Deterministic for a given seed.
// Positives are selected first and are not drawn again as negatives; a proposal that is among
// the top boxes of several instances is used once.
Result<SelectedSamples> SelectTrainingSamples(const std::vector<ScoredBox>& proposals,
                                              const Sample& gt,
                                              const std::vector<int>& range_limits,
                                              const SampleSelectionParams& params,
                                              std::uint64_t seed);

}  // namespace tod
