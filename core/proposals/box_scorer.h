// Scores windows on one region map (ALGORITHM.md §4.2 step 4) and refines them (step 7). All
// per-map work - orientation, edge groups, integral images, run indexes - happens once in the
// constructor; scoring a window allocates nothing and leaves early through integral images.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/proposals/containment_bound.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/edge_groups.h"

namespace tod {

// Inclusive pixel range [c0, c1] x [r0, r1], the form Edge Boxes scores.
struct ScoreWindow {
  int r0 = 0, c0 = 0, r1 = 0, c1 = 0;
  float score = 0.f;
};

class BoxScorer {
 public:
  // edge_map normalised to max 1 (non-finite values count as 0); params assumed valid
  // (ValidateEdgeBoxParams).
  BoxScorer(const cv::Mat1f& edge_map, const EdgeBoxParams& params);

  // Clamps the window to the map and sets its score (0 when below min_score or empty). With
  // bar >= 0 the caller only asks whether the score exceeds bar: a window that provably does
  // not gets score 0 without finishing its walk; one that does gets its exact score.
  void Score(ScoreWindow& window, float bar = -1.f);
  // Coordinate search on the four sides with halving steps, accepting improvements.
  void Refine(ScoreWindow& window);

  int width() const { return width_; }
  int height() const { return height_; }
  const EdgeGroups& groups() const { return groups_; }
  // How many Score calls got past the integral-image early exit.
  long long past_early_exit() const { return past_early_exit_; }

 private:
  // The real constructor, for a map already free of NaN / inf.
  BoxScorer(const cv::Mat1f& finite_edge_map, const EdgeBoxParams& params, int finite_tag);

  // Per-group data the walk touches, packed into one cache line fetch.
  struct Node {
    std::uint32_t stamp = 0;  // == stamp_ when the group is in the current walk
    int slot = 0;             // its entry in walk_
    int anchor_x = 0, anchor_y = 0;
    float magnitude = 0.f;
  };
  struct Affinity {
    int target = 0;
    float value = 0.f;
  };
  struct WalkEntry {
    int group = 0;
    float weight = 0.f;
    bool inside = false;  // anchored inside the box: its weighted magnitude is subtracted
    bool queued = false;
  };

  void BuildIntegralImages(const cv::Mat1f& edge_map);
  void BuildRunIndexes();
  void BuildWalkGraph();
  // Sum over the inclusive rectangle of a column-major (width+1) x (height+1) integral image.
  double RectSum(const std::vector<double>& integral, int r0, int c0, int r1, int c1) const;
  bool AnchoredInside(const Node& n, const ScoreWindow& w) const {
    return n.anchor_x >= w.c0 && n.anchor_x <= w.c1 && n.anchor_y >= w.r0 && n.anchor_y <= w.r1;
  }
  // The boundary-affinity walk of a clamped window whose inside magnitude v passed the early
  // exit; returns the final score (0 below min_score).
  float ScoreAfterEarlyExit(const ScoreWindow& w, double v, float norm, float bar);
  // True when a box whose remaining magnitude is v_left certainly scores below min_score or
  // not above bar. Evaluated exactly as the final score is, so early stops never disagree with
  // a finished walk; v_left only decreases during a walk and the expression is monotone in it.
  bool Hopeless(double v_left, float norm, float bar) const {
    const float score = static_cast<float>(v_left) * norm;
    return score < params_.min_score || score <= bar;
  }
  void Enqueue(int slot) {
    int tail = queue_head_ + queue_size_;
    if (tail >= ring_size_) tail -= ring_size_;
    queue_[tail] = slot;
    ++queue_size_;
  }
  void AddWalkEntry(int group, float weight, bool inside) {
    Node& node = nodes_[group];
    node.stamp = stamp_;
    node.slot = walk_size_;
    walk_[walk_size_] = WalkEntry{group, weight, inside, true};
    Enqueue(walk_size_);
    ++walk_size_;
    if (inside) removed_ += static_cast<double>(weight) * node.magnitude;
  }

  int width_ = 0;
  int height_ = 0;
  EdgeBoxParams params_;
  float refine_ratio_ = 0.f;  // (1 - alpha) / (1 + alpha), unmodified by the stride factor
  EdgeGroups groups_;
  // Column-major integral images, index c * (height + 1) + r: the grid walks rows innermost.
  std::vector<double> anchor_mag_integral_;  // group magnitudes placed at their anchors
  std::vector<double> edge_mag_integral_;    // M where M > edge_min_mag
  std::vector<float> norm_;                  // (bw + bh)^(-kappa), index bw + bh
  ContainmentBound bound_;                   // skips most walks before they start
  // Runs of equal group id along each row (column): the groups touching a box side are the
  // runs between the run indexes of its two end pixels.
  std::vector<int> row_run_group_, row_run_index_;  // run_index at r * width + c
  std::vector<int> col_run_group_, col_run_index_;  // run_index at c * height + r
  // Affinity graph without the edges that can never carry a weight >= 0.05.
  std::vector<int> walk_edge_begin_;
  std::vector<Affinity> walk_edges_;
  // Scratch of the walk, sized by the group count and reused through stamp_.
  std::vector<Node> nodes_;
  std::vector<WalkEntry> walk_;
  std::vector<int> queue_;  // ring of walk_ slots whose weight must be propagated
  int walk_size_ = 0;
  int queue_head_ = 0, queue_size_ = 0, ring_size_ = 0;
  std::uint32_t stamp_ = 0;
  double removed_ = 0.0;  // running sum of weight * magnitude over walked groups inside the box
  long long past_early_exit_ = 0;
};

}  // namespace tod
