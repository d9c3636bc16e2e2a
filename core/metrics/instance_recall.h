// Instance-level recall of ranked proposals (ALGORITHM.md §8.2): pixel-count box IoU, strict
// IoU > tau; recall vs N at tau 0.7; recall vs tau at N = 1000; average recall over
// tau = 0.50 ... 1.00 (11 values) at N = 200 ... 1000.
#pragma once

#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

class RecallAccumulator {
 public:
  // max_proposals: the largest N ever asked for (1000 in the paper).
  explicit RecallAccumulator(int max_proposals = 1000);
  // proposals: ranked, best first (only the first max_proposals are looked at).
  // gt_boxes: the frame's obstacle instances. Frames without instances add nothing.
  // IoU is BoxIoU: with half-open boxes that is the pixel-count IoU of the two pixel sets.
  void Add(const std::vector<Box>& ranked_proposals, const std::vector<Box>& gt_boxes);
  // As Add, but first clips every box to the image [0, width) x [0, height), as the original
  // evaluation counts only pixels inside the image. Error for a non-positive image size.
  Status Add(const std::vector<Box>& ranked_proposals, const std::vector<Box>& gt_boxes,
             int image_width, int image_height);

  int instances() const { return static_cast<int>(best_rank_iou_.size()); }
  int max_proposals() const { return max_proposals_; }
  // Fraction of instances with a proposal among the first n having IoU > tau (strict).
  // n is clamped to [0, max_proposals]; 0 when there are no instances.
  double Recall(int n, double tau) const;
  // Mean over tau in {0.50, 0.55, ..., 1.00} of Recall(n, tau).
  double AverageRecall(int n) const;
  // Best IoU of instance i (in order of addition) among the first n proposals; 0 if none.
  double BestIoU(int instance, int n) const;

 private:
  int max_proposals_;
  // Per instance: for each rank r < max_proposals, the best IoU seen among proposals 0..r.
  // Stored compactly as the sequence of (rank, iou) where the running maximum increases.
  std::vector<std::vector<std::pair<int, double>>> best_rank_iou_;
};

// The IoU thresholds of the AR definition: 0.50, 0.55, ..., 1.00.
const std::vector<double>& RecallIouThresholds();

}  // namespace tod
