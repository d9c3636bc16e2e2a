#include "core/proposals/box_scorer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "core/proposals/fresh_buffer.h"
#include "core/proposals/refinement_schedule.h"

namespace tod {
namespace {

// Max-product weights below this are not propagated further (§4.2.4, as in Edge Boxes).
constexpr float kMinPathWeight = 0.05f;

EdgeGroupParams GroupParamsOf(const EdgeBoxParams& p) {
  return {p.edge_min_mag, p.edge_merge_thr, p.cluster_min_mag, p.gamma};
}

// NaN or infinite edge values would poison orientations, sums and finally the score order:
// they count as "no edge". Maps are normally finite already; then the map itself is used (the
// scorer only reads it during construction), which spares the copy - unless it is a view into a
// larger matrix: the orientation's smoothing would read the parent's pixels beyond its border
// where the copy has reflected ones.
cv::Mat1f FiniteCopy(const cv::Mat1f& map) {
  std::uint32_t non_finite = 0;
  for (int r = 0; r < map.rows && non_finite == 0; ++r) {
    const float* row = map[r];
    // NaN and +-inf are the floats with an all-ones exponent; the branch-free integer test
    // vectorises.
    for (int c = 0; c < map.cols; ++c) {
      non_finite |= (std::bit_cast<std::uint32_t>(row[c]) & 0x7f800000u) == 0x7f800000u;
    }
  }
  if (non_finite == 0 && !map.isSubmatrix()) return map;
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
      skip_groupless_windows_(params.min_score > 1e-6f) {
  auto tables = std::make_shared<Tables>();
  Tables& t = *tables;
  // Every table below only changes at edge pixels (a few % of the map): they are all built from
  // the edge-pixel lists the grouping makes (t.groups.edges, pixels > edge_min_mag as in the
  // score), and orientation is only computed at the pixels grouping reads it at.
  t.groups = BuildEdgeGroups(edge_map, GroupParamsOf(params));
  BuildIntegralImages(t);
  t.bound = ContainmentBound(t.groups, t.groups.edges);
  BuildRunIndexes(t);
  t.norm.resize(static_cast<size_t>(width_ + height_) / 2 + 2);
  t.norm[0] = 0.f;  // a box narrower than 3 x 3 pixels has no inner part to normalise: score 0
  for (size_t i = 1; i < t.norm.size(); ++i) {
    t.norm[i] = std::pow(1.f / static_cast<float>(i), params.kappa);
  }
  BuildWalkGraph(t);
  tables_ = std::move(tables);
  t_ = tables_.get();
}

void BoxScorer::BuildWalkGraph(Tables& t) {
  const int n = t.groups.count() + 1;
  nodes_.assign(n, Node{});
  for (int g = 1; g < n; ++g) {
    nodes_[g].anchor_x = t.groups.anchor_x[g];
    nodes_[g].anchor_y = t.groups.anchor_y[g];
    nodes_[g].magnitude = t.groups.magnitude[g];
  }
  // A walk weight is at most 1, so an edge with affinity < 0.05 never passes the 0.05 cut.
  t.walk_edges.clear();
  for (int g = 0; g < n; ++g) {
    nodes_[g].edge_begin = static_cast<int>(t.walk_edges.size());
    for (int k = t.groups.affinity_begin[g]; k < t.groups.affinity_begin[g + 1]; ++k) {
      if (t.groups.affinity_value[k] >= kMinPathWeight) {
        t.walk_edges.push_back({t.groups.affinity_target[k], t.groups.affinity_value[k]});
      }
    }
    nodes_[g].edge_end = static_cast<int>(t.walk_edges.size());
  }
  queue_.assign(n, 0);  // a group is queued at most once at a time
  ring_size_ = n;
}

void BoxScorer::BuildIntegralImages(Tables& t) {
  // Column by column: integral = left column + running sum of this column's values (the group
  // magnitude at each anchor; M at each edge pixel). Between two edge pixels (anchors are edge
  // pixels too) the running sums are constant, so the column is a vectorisable add of the left
  // column and a constant. Exact: each entry is still left + running sum, with the running sum
  // accumulated over the same non-zero terms in the same (row) order; the zeros it skips would
  // leave a non-negative double sum unchanged.
  const EdgePixels& edges = t.groups.edges;
  const size_t stride = static_cast<size_t>(height_) + 1;
  const size_t n = (static_cast<size_t>(width_) + 1) * stride;
  ReserveFresh(t.anchor_mag_integral, n);
  ReserveFresh(t.edge_mag_integral, n);
  Append(t.anchor_mag_integral, stride);  // column 0: zero
  Append(t.edge_mag_integral, stride);
  for (int c = 1; c <= width_; ++c) {
    double* anchor = Append(t.anchor_mag_integral, stride);  // row 0: zero
    double* edge = Append(t.edge_mag_integral, stride);
    const double* anchor_left = anchor - stride;
    const double* edge_left = edge - stride;
    double anchor_sum = 0.0, edge_sum = 0.0;
    int r = 1;
    const auto fill_to = [&](int end) {
      for (; r < end; ++r) {
        anchor[r] = anchor_left[r] + anchor_sum;
        edge[r] = edge_left[r] + edge_sum;
      }
    };
    for (int i = edges.col_begin[c - 1]; i < edges.col_begin[c]; ++i) {
      const int row = edges.col_row[i];
      fill_to(row + 1);  // rows before the first integral row that includes the pixel
      edge_sum += static_cast<double>(edges.col_value[i]);
      const int s = t.groups.ids(row, c - 1);
      if (s > 0 && t.groups.anchor_x[s] == c - 1 && t.groups.anchor_y[s] == row) {
        anchor_sum += static_cast<double>(t.groups.magnitude[s]);
      }
    }
    fill_to(height_ + 1);
  }
}

namespace {

// Appends the runs of non-zero ids of one line to `runs`, plus the sentinel. The line is given
// by its edge pixels (positions `at` ascending; ids of all other pixels are 0): id_at(i) is the
// id at position i.
template <typename Run, typename IdAt>
void RunsOfLine(const int* at, int count, const IdAt& id_at, std::vector<Run>& runs) {
  const size_t first = runs.size();
  for (int k = 0; k < count; ++k) {
    const int i = at[k];
    const int id = id_at(i);
    if (id <= 0) continue;
    // The previous pixel continues the line's last run when that run ends there with the same id.
    if (runs.size() > first && runs.back().last == i - 1 && runs.back().group == id) {
      runs.back().last = i;
      continue;
    }
    runs.push_back(Run{i, i, id});
  }
  constexpr int kBeyond = std::numeric_limits<int>::max();
  runs.push_back(Run{kBeyond, kBeyond, 0});
}

}  // namespace

void BoxScorer::BuildRunIndexes(Tables& t) {
  const cv::Mat1i& ids = t.groups.ids;
  const EdgePixels& edges = t.groups.edges;
  t.row_runs.clear();
  t.col_runs.clear();
  t.row_begin.assign(static_cast<size_t>(height_) + 1, 0);
  t.col_begin.assign(static_cast<size_t>(width_) + 1, 0);
  for (int r = 0; r < height_; ++r) {
    const int begin = edges.row_begin[r];
    const int* row = ids[r];
    t.row_begin[r] = static_cast<int>(t.row_runs.size());
    RunsOfLine(
        edges.row_col.data() + begin, edges.row_begin[r + 1] - begin,
        [row](int c) { return row[c]; }, t.row_runs);
  }
  t.row_begin[height_] = static_cast<int>(t.row_runs.size());
  for (int c = 0; c < width_; ++c) {
    const int begin = edges.col_begin[c];
    t.col_begin[c] = static_cast<int>(t.col_runs.size());
    RunsOfLine(
        edges.col_row.data() + begin, edges.col_begin[c + 1] - begin,
        [&ids, c](int r) { return ids(r, c); }, t.col_runs);
  }
  t.col_begin[width_] = static_cast<int>(t.col_runs.size());
}

const BoxScorer::Run* BoxScorer::FirstEndingAtOrAfter(const std::vector<Run>& runs, int begin,
                                                      int end, int at) {
  // Up to this many runs a line is scanned: the scan's loads are consecutive, the search's
  // branches unpredictable.
  constexpr int kScannedRuns = 16;
  const Run* run = runs.data() + begin;
  if (end - begin <= kScannedRuns) {
    while (run->last < at) ++run;  // the sentinel's last lies beyond every position
    return run;
  }
  return std::partition_point(run, runs.data() + end, [at](const Run& r) { return r.last < at; });
}

double BoxScorer::RectSum(const std::vector<double>& integral, int r0, int c0, int r1,
                          int c1) const {
  const size_t stride = static_cast<size_t>(height_) + 1;
  return RectSumOfColumns(integral.data() + c0 * stride, integral.data() + (c1 + 1) * stride, r0,
                          r1);
}

void BoxScorer::Score(ScoreWindow& w, float bar) { ScoreImpl(w, bar, true); }

void BoxScorer::ScoreImpl(ScoreWindow& w, float bar, bool use_bound) {
  w.score = 0.f;
  w.r0 = std::clamp(w.r0, 0, height_ - 1);
  w.r1 = std::clamp(w.r1, 0, height_ - 1);
  w.c0 = std::clamp(w.c0, 0, width_ - 1);
  w.c1 = std::clamp(w.c1, 0, width_ - 1);
  if (w.r1 < w.r0 || w.c1 < w.c0) return;
  // The centre box of half the size (offset by a quarter), whose edges are subtracted (§4.2.4).
  const int half_h = (w.r1 - w.r0) / 2, half_w = (w.c1 - w.c0) / 2;
  const int inner_r0 = w.r0 + half_h / 2, inner_c0 = w.c0 + half_w / 2;
  const int inner_r1 = inner_r0 + half_h, inner_c1 = inner_c0 + half_w;
  const float norm = t_->norm[half_w + half_h];
  // The containment bound ends most windows here, before the exact sums and the walk.
  if (use_bound &&
      Hopeless(t_->bound.Bound(w.r0, w.c0, w.r1, w.c1, inner_r0, inner_c0, inner_r1, inner_c1),
               norm, bar)) {
    return;
  }
  w.score = ScoreAfterBound(w, inner_r0, inner_c0, inner_r1, inner_c1, norm, bar);
}

std::int64_t BoxScorer::HopefulThreshold(float norm, float bar) {
  if (threshold_cache_.norm != norm || threshold_cache_.bar != bar) {
    threshold_cache_ = CachedThreshold{
        norm, bar, t_->bound.SmallestHopeful([&](double v) { return Hopeless(v, norm, bar); })};
  }
  return threshold_cache_.fixed;
}

int BoxScorer::ScoreColumn(int x, int box_width, int box_height, int stride_y,
                           const RowRanges* tops, float bar, std::vector<ScoreWindow>& nonzero,
                           std::vector<int>* rows) {
  int visited = 0;
  // Score() on each window of the column, with the per-column work hoisted: the clamped
  // columns, the centre box's columns and the bound's integral-image columns.
  const int c0 = std::clamp(x, 0, width_ - 1), c1 = std::clamp(x + box_width, 0, width_ - 1);
  const int half_w = (c1 - c0) / 2;
  const int inner_c0 = c0 + half_w / 2, inner_c1 = inner_c0 + half_w;
  const ContainmentBound::Columns columns = t_->bound.ColumnsOf(c0, c1, inner_c0, inner_c1);
  int y = 0;
  const auto score_rest = [&](int r0, int r1, int inner_r0, int inner_r1, float norm) {
    const ScoreWindow w{r0, c0, r1, c1, 0.f};
    const float score = ScoreAfterBound(w, inner_r0, inner_c0, inner_r1, inner_c1, norm, bar);
    if (score <= 0.f) return;
    nonzero.push_back(ScoreWindow{r0, c0, r1, c1, score});
    if (rows != nullptr) rows->push_back(y / stride_y);
  };
  // The first grid row at or after `row`.
  const auto grid_row_from = [stride_y](int row) {
    return row <= 0 ? 0 : (row + stride_y - 1) / stride_y * stride_y;
  };
  const int y_end = height_ - box_height + stride_y;
  // Windows that need no clamping share their size, so the bound test is one integer compare
  // against the threshold that Hopeless() puts on the fixed-point bound.
  const int unclamped_end = std::min(y_end, height_ - box_height);
  if (box_height >= 0 && unclamped_end > 0) {
    const int half_h = box_height / 2, inner_offset = half_h / 2;
    const float norm = t_->norm[half_w + half_h];
    const std::int64_t threshold = HopefulThreshold(norm, bar);
    // Three passes over the column, each window in grid order as Score() would take it; a pass
    // only keeps the windows the next one needs. Why it is faster: the windows that pass the
    // bound are scattered over the column, so their integral-image loads miss the cache. Between
    // walks (long dependent chains that fill the out-of-order window) each such miss was waited
    // for on its own; in a pass of sums alone the iterations are independent and the misses of
    // several windows overlap. Why it is exact: every window still gets the same operations on
    // the same values, the walks run in the same order, and hits are appended in the same order.
    reached_.clear();
    const auto grid_rows = [&](int begin, int end) {
      end = std::min(end, unclamped_end);
      const int first = grid_row_from(begin);
      return first < end ? (end - first + stride_y - 1) / stride_y : 0;
    };
    const auto scan = [&](int begin, int end) {
      end = std::min(end, unclamped_end);
      for (y = grid_row_from(begin); y < end; y += stride_y) {
        const int inner_r0 = y + inner_offset;
        if (t_->bound.Reaches(columns, y, y + box_height, inner_r0, inner_r0 + half_h, threshold)) {
          reached_.push_back(y);
        }
      }
    };
    const std::pair<int, int> whole_column(0, unclamped_end);
    const std::pair<int, int>* const admitted_begin = tops ? tops->data() : &whole_column;
    const std::pair<int, int>* const admitted_end =
        tops ? tops->data() + tops->size() : &whole_column + 1;
    // Every admitted window counts as visited, whether the bound or the interior test decided it.
    for (const auto* a = admitted_begin; a != admitted_end; ++a)
      visited += grid_rows(a->first, a->second);
    if (threshold == ContainmentBound::kNever) {
      // No window of this size can pass: the bound decided them all.
    } else if (skip_groupless_windows_ &&
               t_->bound.InteriorTops(c0, c1, box_height, kMaxListedGroups, interior_tops_,
                                      &contained_steps_)) {
      // Only windows that can hold a whole group: the admitted ranges intersected with those,
      // both sorted and disjoint, so the grid rows are scanned in the same ascending order. The
      // listed groups give each window the exact magnitude its interior holds, a tighter bound
      // than the corner integrals: on 8 real frames it skips a sixth of the walks the corners let
      // through (docs/findings.md#the-walks-tables), and the windows it skips score 0 either way.
      std::int64_t contained = 0;
      auto step = contained_steps_.cbegin();
      const auto scan_contained = [&](int begin, int end) {
        end = std::min(end, unclamped_end);
        for (y = grid_row_from(begin); y < end; y += stride_y) {
          for (; step != contained_steps_.cend() && step->y <= y; ++step) contained += step->delta;
          const int inner_r0 = y + inner_offset;
          if (t_->bound.ContainedReaches(columns, contained, inner_r0, inner_r0 + half_h,
                                         threshold)) {
            reached_.push_back(y);
          }
        }
      };
      const auto* a = admitted_begin;
      auto g = interior_tops_.begin();
      while (a != admitted_end && g != interior_tops_.end()) {
        const int begin = std::max(a->first, g->first), end = std::min(a->second, g->second);
        if (begin < end) scan_contained(begin, end);
        (a->second < g->second) ? void(++a) : void(++g);
      }
    } else {
      for (const auto* a = admitted_begin; a != admitted_end; ++a) scan(a->first, a->second);
    }
    // Pass 2: v of ScoreAfterBound and its early exit.
    const size_t stride = static_cast<size_t>(height_) + 1;
    const double* const anchor_left = t_->anchor_mag_integral.data() + c0 * stride;
    const double* const anchor_right = t_->anchor_mag_integral.data() + (c1 + 1) * stride;
    const double* const edge_left = t_->edge_mag_integral.data() + inner_c0 * stride;
    const double* const edge_right = t_->edge_mag_integral.data() + (inner_c1 + 1) * stride;
    hopeful_.clear();
    for (size_t i = 0; i < reached_.size(); ++i) {
      const int r0 = reached_[i], r1 = r0 + box_height;
      const int inner_r0 = r0 + inner_offset, inner_r1 = inner_r0 + half_h;
      const double v = RectSumOfColumns(anchor_left, anchor_right, r0, r1) -
                       RectSumOfColumns(edge_left, edge_right, inner_r0, inner_r1);
      if (!Hopeless(v, norm, bar)) hopeful_.push_back(Hopeful{r0, v});
    }
    // Pass 3: the walks of the windows past the early exit.
    for (size_t i = 0; i < hopeful_.size(); ++i) {
      const int r0 = hopeful_[i].r0;
      ++past_early_exit_;
      const ScoreWindow w{r0, c0, r0 + box_height, c1, 0.f};
      const float score = ScoreAfterEarlyExit(w, hopeful_[i].v, norm, bar);
      if (score <= 0.f) continue;
      nonzero.push_back(ScoreWindow{w.r0, w.c0, w.r1, w.c1, score});
      if (rows != nullptr) rows->push_back(r0 / stride_y);
    }
  }
  for (y = grid_row_from(unclamped_end); y < y_end; y += stride_y) {  // the clamped windows
    ++visited;
    const int r0 = std::min(y, height_ - 1), r1 = std::min(y + box_height, height_ - 1);
    const int half_h = (r1 - r0) / 2;
    const int inner_r0 = r0 + half_h / 2, inner_r1 = inner_r0 + half_h;
    const float norm = t_->norm[half_w + half_h];
    if (Hopeless(t_->bound.Bound(columns, r0, r1, inner_r0, inner_r1), norm, bar)) continue;
    score_rest(r0, r1, inner_r0, inner_r1, norm);
  }
  return visited;
}

float BoxScorer::ScoreAfterBound(const ScoreWindow& w, int inner_r0, int inner_c0, int inner_r1,
                                 int inner_c1, float norm, float bar) {
  // Magnitude of the groups anchored inside, minus the edges of the centre box: edges there say
  // nothing about an object boundary (§4.2.4).
  const double v = RectSum(t_->anchor_mag_integral, w.r0, w.c0, w.r1, w.c1) -
                   RectSum(t_->edge_mag_integral, inner_r0, inner_c0, inner_r1, inner_c1);
  // The walk can only lower v: skip it when v alone cannot score highly (or beat the bar).
  if (Hopeless(v, norm, bar)) return 0.f;
  ++past_early_exit_;
  return ScoreAfterEarlyExit(w, v, norm, bar);
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
  queue_head_ = 0;
  queue_size_ = 0;
  removed_ = 0.0;
  const auto add_boundary_runs = [&](const Run* run, int last) {
    for (; run->start <= last; ++run) {
      const int g = run->group;
      if (nodes_[g].stamp != stamp_) AddWalkEntry(g, 1.f, AnchoredInside(nodes_[g], w));
    }
  };
  const Tables& t = *t_;
  const auto row_side = [&t](int r, int c0) {
    return FirstEndingAtOrAfter(t.row_runs, t.row_begin[r], t.row_begin[r + 1], c0);
  };
  const auto col_side = [&t](int c, int r0) {
    return FirstEndingAtOrAfter(t.col_runs, t.col_begin[c], t.col_begin[c + 1], r0);
  };
  // Check after every side: half of the walks end here, often before all four are read.
  add_boundary_runs(row_side(w.r0, w.c0), w.c1);  // top
  if (Hopeless(v - removed_, norm, bar)) return 0.f;
  add_boundary_runs(row_side(w.r1, w.c0), w.c1);  // bottom
  if (Hopeless(v - removed_, norm, bar)) return 0.f;
  add_boundary_runs(col_side(w.c0, w.r0), w.r1);  // left
  if (Hopeless(v - removed_, norm, bar)) return 0.f;
  add_boundary_runs(col_side(w.c1, w.r0), w.r1);  // right
  if (Hopeless(v - removed_, norm, bar)) return 0.f;

  while (queue_size_ > 0) {
    const int s = queue_[queue_head_];
    queue_head_ = queue_head_ + 1 == ring_size_ ? 0 : queue_head_ + 1;
    --queue_size_;
    nodes_[s].queued = false;
    const float weight = nodes_[s].weight;
    const Affinity* edge = t_->walk_edges.data() + nodes_[s].edge_begin;
    const Affinity* const end = t_->walk_edges.data() + nodes_[s].edge_end;
    for (; edge != end; ++edge) {
      const float wt = weight * edge->value;
      if (wt < kMinPathWeight) continue;
      Node& node = nodes_[edge->target];
      if (node.stamp == stamp_) {
        if (wt <= node.weight) continue;
        // Only inside groups can improve: boundary groups already hold weight 1.
        removed_ += static_cast<double>(wt - node.weight) * node.magnitude;
        node.weight = wt;
        if (!node.queued) {
          node.queued = true;
          Enqueue(edge->target);
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
  const RefinementSchedule schedule =
      ScheduleRefinement(box.r1 - box.r0, box.c1 - box.c0, refine_ratio_);
  // Tries moving one side outwards, then inwards; keeps the better window if it improves.
  // Candidates only need to beat box.score, so that is the bar for their walks.
  auto search = [this, &box](int ScoreWindow::*side, int step) {
    ScoreWindow candidate = box;
    candidate.*side -= step;
    ScoreImpl(candidate, box.score, false);
    if (candidate.score <= box.score) {
      candidate = box;
      candidate.*side += step;
      ScoreImpl(candidate, box.score, false);
    }
    if (candidate.score > box.score) box = candidate;
  };
  for (int i = 0; i < schedule.count; ++i) {
    search(&ScoreWindow::r0, schedule.row_step[i]);   // top: grow = move up
    search(&ScoreWindow::r1, -schedule.row_step[i]);  // bottom: grow = move down
    search(&ScoreWindow::c0, schedule.col_step[i]);
    search(&ScoreWindow::c1, -schedule.col_step[i]);
  }
}

}  // namespace tod
