// Scores windows on one region map (ALGORITHM.md §4.2 step 4) and refines them (step 7). All
// per-map work - orientation, edge groups, integral images, run indexes - happens once in the
// constructor; scoring a window allocates nothing and leaves early through integral images.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "core/proposals/containment_bound.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/proposals/edge_groups.h"
#include "core/proposals/window_admission.h"

namespace tod {

// Inclusive pixel range [c0, c1] x [r0, r1], the form Edge Boxes scores.
struct ScoreWindow {
  int r0 = 0, c0 = 0, r1 = 0, c1 = 0;
  float score = 0.f;
};

// Copies are cheap: they share the per-map tables and own only the walk scratch, so a threaded
// caller gives each thread its own copy.
class BoxScorer {
 public:
  // edge_map normalised to max 1 (non-finite values count as 0); params assumed valid
  // (ValidateEdgeBoxParams).
  BoxScorer(const cv::Mat1f& edge_map, const EdgeBoxParams& params);

  // Clamps the window to the map and sets its score (0 when below min_score or empty). With
  // bar >= 0 the caller only asks whether the score exceeds bar: a window that provably does
  // not gets score 0 without finishing its walk; one that does gets its exact score.
  void Score(ScoreWindow& window, float bar = -1.f);
  // Scores the sliding-window column at x of one window shape (nominal extent box_width x
  // box_height, row stride stride_y; rows y = 0, stride_y, ... while y < height - box_height +
  // stride_y) exactly as Score(window, bar) would, and appends the clamped windows with a
  // non-zero score (and, with `rows`, their grid row index y / stride_y): with bar < 0 every
  // window scoring at least min_score, otherwise those scoring above bar. With `tops`, only the
  // unclamped windows whose top row lies in one of those ranges are scored (the clamped ones
  // always are). Returns how many windows it visited.
  int ScoreColumn(int x, int box_width, int box_height, int stride_y, const RowRanges* tops,
                  float bar, std::vector<ScoreWindow>& nonzero, std::vector<int>* rows = nullptr);
  // Coordinate search on the four sides with halving steps, accepting improvements.
  void Refine(ScoreWindow& window);

  int width() const { return width_; }
  int height() const { return height_; }
  const EdgeGroups& groups() const { return t_->groups; }
  // How many scorings ran the boundary-affinity walk (past the bound and the early exit).
  long long past_early_exit() const { return past_early_exit_; }

 private:
  // The real constructor, for a map already free of NaN / inf.
  BoxScorer(const cv::Mat1f& finite_edge_map, const EdgeBoxParams& params, int finite_tag);

  // Everything the walk reads or writes about one group in one aligned 32-byte record, so a
  // visit costs one cache line: whether the group is in the current walk and its weight (the
  // walk state), the inside test, the subtracted magnitude and its walk edges. A separate walk
  // list indexed from here, and the edge offsets in their own table, were two more dependent
  // loads per visited group. Exact: the walk keeps the same values (a weight per walked group),
  // visits the groups in the same queue order and does the same float / double operations.
  struct alignas(32) Node {
    std::uint32_t stamp = 0;  // == stamp_ when the group is in the current walk; then:
    float weight = 0.f;       //   its largest path product so far
    bool queued = false;      //   whether it waits in queue_ to propagate a changed weight
    int anchor_x = 0, anchor_y = 0;
    float magnitude = 0.f;
    int edge_begin = 0, edge_end = 0;  // its walk edges: walk_edges[edge_begin, edge_end)
  };
  struct Affinity {
    int target = 0;
    float value = 0.f;
  };
  // A run of pixels of one group along a row (column): positions [start, last]. The runs of each
  // row (column) are in order and end with a sentinel whose start and last lie beyond every
  // pixel.
  struct Run {
    int start = 0;
    int last = 0;
    int group = 0;
  };

  // Everything derived from the map once; read-only while scoring.
  struct Tables {
    EdgeGroups groups;
    // Column-major integral images, index c * (height + 1) + r: the grid walks rows innermost.
    std::vector<double> anchor_mag_integral;  // group magnitudes placed at their anchors
    std::vector<double> edge_mag_integral;    // M where M > edge_min_mag
    std::vector<float> norm;                  // (bw + bh)^(-kappa), index bw + bh
    ContainmentBound bound;                   // skips most walks before they start
    // Runs of one group (id > 0) along each row (column), in order: row r's runs (and its
    // sentinel) are row_runs[row_begin[r], row_begin[r + 1]), column c's likewise. The groups
    // touching the box side [c0, c1] of row r are those of the runs from the first one that
    // ends at or after c0 while their start is <= c1 (FirstEndingAtOrAfter). A search in the
    // line replaced a dense table of that first run per pixel (8 bytes a pixel, 9 MB for R1 of
    // a real frame, written in full by the constructor and read at a cache miss per side):
    // the runs of real frames' sparse maps, a few per line, stay in cache
    // (docs/findings.md#the-walks-tables).
    std::vector<Run> row_runs, col_runs;
    std::vector<int> row_begin, col_begin;
    // Affinity graph without the edges that can never carry a weight >= 0.05.
    std::vector<Affinity> walk_edges;
  };

  // Score() with the containment bound optional: Refine() skips it, because its candidates lie
  // next to a box that scored, the bound rarely rejects them, and its loads cost more than the
  // walks it saves (measured with bench_proposals_olp).
  void ScoreImpl(ScoreWindow& window, float bar, bool use_bound);
  // From the edge-pixel lists of t.groups (all that changes the sums).
  void BuildIntegralImages(Tables& t);
  void BuildRunIndexes(Tables& t);
  void BuildWalkGraph(Tables& t);
  // Sum over the inclusive rectangle of a column-major (width+1) x (height+1) integral image.
  double RectSum(const std::vector<double>& integral, int r0, int c0, int r1, int c1) const;
  // The same sum from the integral image's columns c0 (`left`) and c1 + 1 (`right`), for loops
  // that keep the columns fixed; RectSum is this, so both give the same double.
  static double RectSumOfColumns(const double* left, const double* right, int r0, int r1) {
    return right[r1 + 1] - right[r0] - left[r1 + 1] + left[r0];
  }
  // The first run of runs[begin, end) (one line with its sentinel, runs in order) that ends at
  // or after position `at`: the sentinel when none does. Short lines are scanned, long ones
  // (dense maps: a checkerboard's rows hold hundreds of runs) searched by halves.
  static const Run* FirstEndingAtOrAfter(const std::vector<Run>& runs, int begin, int end, int at);
  bool AnchoredInside(const Node& n, const ScoreWindow& w) const {
    return n.anchor_x >= w.c0 && n.anchor_x <= w.c1 && n.anchor_y >= w.r0 && n.anchor_y <= w.r1;
  }
  // The exact sums and the walk of a clamped window that passed the containment bound.
  float ScoreAfterBound(const ScoreWindow& w, int inner_r0, int inner_c0, int inner_r1,
                        int inner_c1, float norm, float bar);
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
  void Enqueue(int group) {
    int tail = queue_head_ + queue_size_;
    if (tail >= ring_size_) tail -= ring_size_;
    queue_[tail] = group;
    ++queue_size_;
  }
  void AddWalkEntry(int group, float weight, bool inside) {
    Node& node = nodes_[group];
    node.stamp = stamp_;
    node.weight = weight;
    // A group without walk edges propagates nothing: it needs no turn in the queue.
    node.queued = node.edge_begin != node.edge_end;
    if (node.queued) Enqueue(group);
    if (inside) removed_ += static_cast<double>(weight) * node.magnitude;
  }

  int width_ = 0;
  int height_ = 0;
  EdgeBoxParams params_;
  float refine_ratio_ = 0.f;  // (1 - alpha) / (1 + alpha), unmodified by the stride factor
  // The per-map tables, shared by the copies a multi-threaded caller makes (copies only
  // duplicate the walk scratch).
  std::shared_ptr<const Tables> tables_;
  const Tables* t_ = nullptr;  // tables_.get(), for short access in the hot paths
  // Scratch of the walk, sized by the group count and reused through stamp_.
  std::vector<Node> nodes_;
  std::vector<int> queue_;  // ring of the groups whose weight must be propagated
  int queue_head_ = 0, queue_size_ = 0, ring_size_ = 0;
  std::uint32_t stamp_ = 0;
  double removed_ = 0.0;  // running sum of weight * magnitude over walked groups inside the box
  long long past_early_exit_ = 0;
  // Scratch of ScoreColumn: the grid rows of one column that pass the containment bound, and
  // those of them that pass the early exit, with their v.
  struct Hopeful {
    int r0 = 0;
    double v = 0.0;
  };
  std::vector<int> reached_;
  std::vector<Hopeful> hopeful_;
  RowRanges interior_tops_;  // ContainmentBound::InteriorTops of the column
  std::vector<ContainmentBound::ContainedStep> contained_steps_;  // and its contained magnitude
  // The fixed-point threshold of the last (norm, bar) ScoreColumn asked for (HopefulThreshold):
  // the unclamped columns of a window shape share it, and its binary search (34 steps) took
  // ~12 % of the column scan when it ran per column.
  struct CachedThreshold {
    float norm = -1.f;
    float bar = 0.f;
    std::int64_t fixed = 0;
  };
  CachedThreshold threshold_cache_;
  std::int64_t HopefulThreshold(float norm, float bar);
  // ScoreColumn skips the windows without a whole group in their interior (they score 0) when
  // min_score is positive, so that no rounding residue of v - removed could score; the column
  // is listed only when at most kMaxListedGroups groups start in it.
  bool skip_groupless_windows_ = false;
  static constexpr int kMaxListedGroups = 32;
};

}  // namespace tod
