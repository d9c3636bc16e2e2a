#include "core/metrics/instance_recall.h"

#include <algorithm>
#include <string>

namespace tod {

RecallAccumulator::RecallAccumulator(int max_proposals)
    : max_proposals_(std::max(0, max_proposals)) {}

void RecallAccumulator::Add(const std::vector<Box>& ranked_proposals,
                            const std::vector<Box>& gt_boxes) {
  const auto considered =
      static_cast<int>(std::min(ranked_proposals.size(), static_cast<std::size_t>(max_proposals_)));
  for (const Box& gt : gt_boxes) {
    // Only ranks where the running best strictly improves are kept: the best IoU within the
    // first n proposals is then the last entry with rank < n (a binary search).
    std::vector<std::pair<int, double>> improvements;
    double best = 0.0;
    for (int rank = 0; rank < considered; ++rank) {
      const double iou = BoxIoU(ranked_proposals[rank], gt);
      if (iou > best) {
        best = iou;
        improvements.emplace_back(rank, iou);
      }
    }
    best_rank_iou_.push_back(std::move(improvements));
  }
}

Status RecallAccumulator::Add(const std::vector<Box>& ranked_proposals,
                              const std::vector<Box>& gt_boxes, int image_width, int image_height) {
  if (image_width <= 0 || image_height <= 0) {
    return Status::InvalidArgument("RecallAccumulator::Add: image size " +
                                   std::to_string(image_width) + "x" +
                                   std::to_string(image_height) + " is not positive");
  }
  const auto clip_all = [&](const std::vector<Box>& boxes, std::size_t limit) {
    std::vector<Box> clipped;
    clipped.reserve(std::min(boxes.size(), limit));
    for (std::size_t i = 0; i < boxes.size() && i < limit; ++i) {
      clipped.push_back(ClipToImage(boxes[i], image_width, image_height));
    }
    return clipped;
  };
  Add(clip_all(ranked_proposals, static_cast<std::size_t>(max_proposals_)),
      clip_all(gt_boxes, gt_boxes.size()));
  return Status::Ok();
}

double RecallAccumulator::BestIoU(int instance, int n) const {
  if (instance < 0 || instance >= instances()) return 0.0;
  const auto& improvements = best_rank_iou_[instance];
  const int limit = std::clamp(n, 0, max_proposals_);
  // First entry with rank >= limit; the one before it is the best within ranks < limit.
  const auto after = std::lower_bound(
      improvements.begin(), improvements.end(), limit,
      [](const std::pair<int, double>& entry, int rank) { return entry.first < rank; });
  return after == improvements.begin() ? 0.0 : (after - 1)->second;
}

double RecallAccumulator::Recall(int n, double tau) const {
  if (best_rank_iou_.empty()) return 0.0;
  int hits = 0;
  for (int i = 0; i < instances(); ++i) {
    if (BestIoU(i, n) > tau) ++hits;
  }
  return static_cast<double>(hits) / instances();
}

double RecallAccumulator::AverageRecall(int n) const {
  const std::vector<double>& taus = RecallIouThresholds();
  double sum = 0.0;
  for (const double tau : taus) sum += Recall(n, tau);
  return sum / static_cast<double>(taus.size());
}

const std::vector<double>& RecallIouThresholds() {
  // k / 100 rather than repeated += 0.05: each threshold is the double nearest its decimal, the
  // same double an IoU of e.g. 7/10 evaluates to, so "IoU > 0.7" is false for IoU exactly 0.7.
  static const std::vector<double> taus = [] {
    std::vector<double> v;
    for (int k = 50; k <= 100; k += 5) v.push_back(k / 100.0);
    return v;
  }();
  return taus;
}

}  // namespace tod
