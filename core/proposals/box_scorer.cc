#include "core/proposals/box_scorer.h"

#include <algorithm>
#include <cmath>

#include "core/proposals/edge_orientation.h"

namespace tod {
namespace {

// Max-product weights below this are not propagated further (§4.2.4, as in Edge Boxes).
constexpr float kMinPathWeight = 0.05f;

EdgeGroupParams GroupParamsOf(const EdgeBoxParams& p) {
  return {p.edge_min_mag, p.edge_merge_thr, p.cluster_min_mag, p.gamma};
}

// NaN or infinite edge values would poison orientations, sums and finally the score order:
// they count as "no edge".
cv::Mat1f FiniteCopy(const cv::Mat1f& map) {
  cv::Mat1f out = map.clone();
  for (int r = 0; r < out.rows; ++r) {
    float* row = out[r];
    for (int c = 0; c < out.cols; ++c) {
      if (!std::isfinite(row[c])) row[c] = 0.f;
    }
  }
  return out;
}

}  // namespace

BoxScorer::BoxScorer(const cv::Mat1f& edge_map, const EdgeBoxParams& params)
    : BoxScorer(FiniteCopy(edge_map), params, 0) {}

BoxScorer::BoxScorer(const cv::Mat1f& edge_map, const EdgeBoxParams& params, int /*finite*/)
    : width_(edge_map.cols),
      height_(edge_map.rows),
      params_(params),
      refine_ratio_((1.f - params.alpha) / (1.f + params.alpha)),
      groups_(BuildEdgeGroups(edge_map, ComputeEdgeOrientation(edge_map), GroupParamsOf(params))) {
  BuildIntegralImages(edge_map);
  bound_ = ContainmentBound(groups_, edge_map, params.edge_min_mag);
  BuildRunIndexes();
  norm_.resize(static_cast<size_t>(width_ + height_) / 2 + 2);
  norm_[0] = 0.f;  // a box narrower than 3 x 3 pixels has no inner part to normalise: score 0
  for (size_t i = 1; i < norm_.size(); ++i) {
    norm_[i] = std::pow(1.f / static_cast<float>(i), params.kappa);
  }
  BuildWalkGraph();
}

void BoxScorer::BuildWalkGraph() {
  const int n = groups_.count() + 1;
  nodes_.assign(n, Node{});
  for (int g = 1; g < n; ++g) {
    nodes_[g].anchor_x = groups_.anchor_x[g];
    nodes_[g].anchor_y = groups_.anchor_y[g];
    nodes_[g].magnitude = groups_.magnitude[g];
  }
  // A walk weight is at most 1, so an edge with affinity < 0.05 never passes the 0.05 cut.
  walk_edge_begin_.assign(n + 1, 0);
  walk_edges_.clear();
  for (int g = 0; g < n; ++g) {
    for (int k = groups_.affinity_begin[g]; k < groups_.affinity_begin[g + 1]; ++k) {
      if (groups_.affinity_value[k] >= kMinPathWeight) {
        walk_edges_.push_back({groups_.affinity_target[k], groups_.affinity_value[k]});
      }
    }
    walk_edge_begin_[g + 1] = static_cast<int>(walk_edges_.size());
  }
  walk_.assign(n, WalkEntry{});
  queue_.assign(n, 0);  // a slot is queued at most once at a time
  ring_size_ = n;
}

void BoxScorer::BuildIntegralImages(const cv::Mat1f& edge_map) {
  const size_t stride = static_cast<size_t>(height_) + 1;
  const size_t n = (static_cast<size_t>(width_) + 1) * stride;
  // Per-pixel values first (column-major, offset by one), then the running sums.
  anchor_mag_integral_.assign(n, 0.0);
  edge_mag_integral_.assign(n, 0.0);
  for (int s = 1; s <= groups_.count(); ++s) {
    anchor_mag_integral_[(groups_.anchor_x[s] + 1) * stride + groups_.anchor_y[s] + 1] +=
        groups_.magnitude[s];
  }
  for (int r = 0; r < height_; ++r) {
    const float* e = edge_map[r];
    for (int c = 0; c < width_; ++c) {
      if (e[c] > params_.edge_min_mag) edge_mag_integral_[(c + 1) * stride + r + 1] = e[c];
    }
  }
  for (std::vector<double>* integral : {&anchor_mag_integral_, &edge_mag_integral_}) {
    std::vector<double>& I = *integral;
    for (int c = 1; c <= width_; ++c) {
      double column_sum = 0.0;
      for (int r = 1; r <= height_; ++r) {
        column_sum += I[c * stride + r];
        I[c * stride + r] = I[(c - 1) * stride + r] + column_sum;
      }
    }
  }
}

void BoxScorer::BuildRunIndexes() {
  const cv::Mat1i& ids = groups_.ids;
  row_run_index_.resize(static_cast<size_t>(width_) * height_);
  col_run_index_.resize(static_cast<size_t>(width_) * height_);
  row_run_group_.clear();
  col_run_group_.clear();
  for (int r = 0; r < height_; ++r) {
    for (int c = 0; c < width_; ++c) {
      if (c == 0 || ids(r, c) != ids(r, c - 1)) row_run_group_.push_back(ids(r, c));
      row_run_index_[static_cast<size_t>(r) * width_ + c] =
          static_cast<int>(row_run_group_.size()) - 1;
    }
  }
  for (int c = 0; c < width_; ++c) {
    for (int r = 0; r < height_; ++r) {
      if (r == 0 || ids(r, c) != ids(r - 1, c)) col_run_group_.push_back(ids(r, c));
      col_run_index_[static_cast<size_t>(c) * height_ + r] =
          static_cast<int>(col_run_group_.size()) - 1;
    }
  }
}

double BoxScorer::RectSum(const std::vector<double>& integral, int r0, int c0, int r1,
                          int c1) const {
  const size_t stride = static_cast<size_t>(height_) + 1;
  const size_t left = c0 * stride, right = (c1 + 1) * stride;
  return integral[right + r1 + 1] - integral[right + r0] - integral[left + r1 + 1] +
         integral[left + r0];
}

void BoxScorer::Score(ScoreWindow& w, float bar) {
  w.score = 0.f;
  w.r0 = std::clamp(w.r0, 0, height_ - 1);
  w.r1 = std::clamp(w.r1, 0, height_ - 1);
  w.c0 = std::clamp(w.c0, 0, width_ - 1);
  w.c1 = std::clamp(w.c1, 0, width_ - 1);
  if (w.r1 < w.r0 || w.c1 < w.c0) return;
  // Magnitude of the groups anchored inside, minus the edges of the centre box of half the size
  // (offset by a quarter): edges there say nothing about an object boundary (§4.2.4).
  const int half_h = (w.r1 - w.r0) / 2, half_w = (w.c1 - w.c0) / 2;
  const int inner_r0 = w.r0 + half_h / 2, inner_c0 = w.c0 + half_w / 2;
  const int inner_r1 = inner_r0 + half_h, inner_c1 = inner_c0 + half_w;
  const float norm = norm_[half_w + half_h];
  // The containment bound ends most windows here, before the exact sums and the walk.
  if (Hopeless(bound_.Bound(w.r0, w.c0, w.r1, w.c1, inner_r0, inner_c0, inner_r1, inner_c1), norm,
               bar)) {
    return;
  }
  double v = RectSum(anchor_mag_integral_, w.r0, w.c0, w.r1, w.c1) -
             RectSum(edge_mag_integral_, inner_r0, inner_c0, inner_r1, inner_c1);
  // The walk can only lower v: skip it when v alone cannot score highly (or beat the bar).
  if (Hopeless(v, norm, bar)) return;
  ++past_early_exit_;
  w.score = ScoreAfterEarlyExit(w, v, norm, bar);
}

float BoxScorer::ScoreAfterEarlyExit(const ScoreWindow& w, double v, float norm, float bar) {
  // Groups on any of the four sides get weight 1 (they cross the box boundary); weights
  // propagate by max-product paths through the affinity graph to groups anchored inside
  // (products < 0.05 are cut), whose weighted magnitudes are subtracted from v (§4.2.4).
  // Edge Boxes re-scans its list from an improved group onwards; a queue of the groups whose
  // weight changed reaches the same fixpoint (the largest path product per group) with less
  // work. Weights only grow, so the subtracted sum only grows: as soon as (v - removed) * norm
  // is below min_score (or not above the bar) the outcome is certain and the walk stops. The
  // final score is (v - removed) * norm with this running sum.
  if (++stamp_ == 0) {  // wrapped: forget every old stamp
    for (Node& node : nodes_) node.stamp = 0;
    stamp_ = 1;
  }
  walk_size_ = 0;
  queue_head_ = 0;
  queue_size_ = 0;
  removed_ = 0.0;
  const auto add_boundary_runs = [&](const std::vector<int>& run_group, int first, int last) {
    for (int i = first; i <= last; ++i) {
      const int g = run_group[i];
      if (g > 0 && nodes_[g].stamp != stamp_) AddWalkEntry(g, 1.f, AnchoredInside(nodes_[g], w));
    }
  };
  const size_t top = static_cast<size_t>(w.r0) * width_;
  const size_t bottom = static_cast<size_t>(w.r1) * width_;
  const size_t left = static_cast<size_t>(w.c0) * height_;
  const size_t right = static_cast<size_t>(w.c1) * height_;
  // Check after every side: half of the walks end here, often before all four are read.
  add_boundary_runs(row_run_group_, row_run_index_[top + w.c0], row_run_index_[top + w.c1]);
  if (Hopeless(v - removed_, norm, bar)) return 0.f;
  add_boundary_runs(row_run_group_, row_run_index_[bottom + w.c0], row_run_index_[bottom + w.c1]);
  if (Hopeless(v - removed_, norm, bar)) return 0.f;
  add_boundary_runs(col_run_group_, col_run_index_[left + w.r0], col_run_index_[left + w.r1]);
  if (Hopeless(v - removed_, norm, bar)) return 0.f;
  add_boundary_runs(col_run_group_, col_run_index_[right + w.r0], col_run_index_[right + w.r1]);
  if (Hopeless(v - removed_, norm, bar)) return 0.f;

  while (queue_size_ > 0) {
    const int slot = queue_[queue_head_];
    queue_head_ = queue_head_ + 1 == ring_size_ ? 0 : queue_head_ + 1;
    --queue_size_;
    walk_[slot].queued = false;
    const float weight = walk_[slot].weight;
    const int s = walk_[slot].group;
    const Affinity* edge = walk_edges_.data() + walk_edge_begin_[s];
    const Affinity* const end = walk_edges_.data() + walk_edge_begin_[s + 1];
    for (; edge != end; ++edge) {
      const float wt = weight * edge->value;
      if (wt < kMinPathWeight) continue;
      const Node& node = nodes_[edge->target];
      if (node.stamp == stamp_) {
        WalkEntry& entry = walk_[node.slot];
        if (wt <= entry.weight) continue;
        // Only inside groups can improve: boundary groups already hold weight 1.
        removed_ += static_cast<double>(wt - entry.weight) * node.magnitude;
        entry.weight = wt;
        if (!entry.queued) {
          entry.queued = true;
          Enqueue(node.slot);
        }
      } else if (AnchoredInside(node, w)) {
        AddWalkEntry(edge->target, wt, true);
      } else {
        continue;
      }
      if (Hopeless(v - removed_, norm, bar)) return 0.f;
    }
  }
  const float score = static_cast<float>(v - removed_) * norm;
  return score < params_.min_score ? 0.f : score;
}

void BoxScorer::Refine(ScoreWindow& box) {
  // Steps from the unmodified ratio (1 - alpha) / (1 + alpha): MS changes only the grid (§4.2.7).
  int row_step = static_cast<int>(static_cast<float>(box.r1 - box.r0) * refine_ratio_);
  int col_step = static_cast<int>(static_cast<float>(box.c1 - box.c0) * refine_ratio_);
  // Tries moving one side outwards, then inwards; keeps the better window if it improves.
  // Candidates only need to beat box.score, so that is the bar for their walks.
  auto search = [this, &box](int ScoreWindow::*side, int step) {
    ScoreWindow candidate = box;
    candidate.*side -= step;
    Score(candidate, box.score);
    if (candidate.score <= box.score) {
      candidate = box;
      candidate.*side += step;
      Score(candidate, box.score);
    }
    if (candidate.score > box.score) box = candidate;
  };
  while (true) {
    row_step /= 2;
    col_step /= 2;
    if (row_step <= 2 && col_step <= 2) break;
    row_step = std::max(1, row_step);
    col_step = std::max(1, col_step);
    search(&ScoreWindow::r0, row_step);   // top: grow = move up
    search(&ScoreWindow::r1, -row_step);  // bottom: grow = move down
    search(&ScoreWindow::c0, col_step);
    search(&ScoreWindow::c1, -col_step);
  }
}

}  // namespace tod
