#include "core/proposals/window_scan.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <numeric>
#include <thread>

#include "core/proposals/refinement_schedule.h"
#include "core/proposals/window_grid.h"

namespace tod {

int ResolveThreadCount(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

namespace {

// One grid column: a window shape and the column position x.
struct GridColumn {
  int shape = 0;
  int x = 0;
};

// Work is handed out in chunks: large enough to amortise the hand-out, small enough to balance
// the threads (the cost of a column or a refinement varies by orders of magnitude).
constexpr size_t kColumnsPerChunk = 16;
constexpr size_t kRefinementsPerChunk = 64;

Box ToBox(const ScoreWindow& w) { return Box{w.c0, w.r0, w.c1 - w.c0 + 1, w.r1 - w.r0 + 1}; }

using Clock = std::chrono::steady_clock;

// A step through 0 .. n - 1 that visits every index once and spreads consecutive visits far
// apart (a step near n / phi, coprime with n): the hand-out order when a deadline may cut a pass
// short, so that the chunks left out are scattered over the pass instead of being its tail.
size_t ScatteredStep(size_t n) {
  if (n <= 2) return 1;
  size_t step = std::max<size_t>(1, static_cast<size_t>(static_cast<double>(n) * 0.6180339887));
  while (std::gcd(step, n) != 1) ++step;
  return step % n == 0 ? 1 : step;
}

struct ChunkRun {
  long long walks = 0;  // walks the scorer copies ran
  size_t skipped = 0;   // chunks not run because the deadline had passed
};

// Runs body(scorer, worker, chunk) for chunk = 0 .. chunks - 1 on `threads` threads (the
// caller's included), each with its own copy of the scorer and its own index worker in
// [0, threads) (the caller's is 0). Which thread runs which chunk varies, so bodies write only to
// their chunk's own output or to their worker's. With a deadline (not Clock::time_point::max()),
// chunks are handed out in a scattered order and none is started once it has passed.
template <typename Body>
ChunkRun ParallelChunks(const BoxScorer& prototype, size_t chunks, int threads,
                        Clock::time_point deadline, Body body) {
  const bool limited = deadline != Clock::time_point::max();
  const size_t step = limited ? ScatteredStep(chunks) : 1;
  std::atomic<size_t> next_turn{0};
  std::atomic<size_t> done{0};
  std::atomic<long long> walks{0};
  std::atomic<bool> failed{false};
  std::exception_ptr failure;
  const auto work = [&](size_t worker) {
    try {
      BoxScorer scorer(prototype);  // own walk scratch, shared map tables
      for (size_t turn = next_turn++; turn < chunks && !failed; turn = next_turn++) {
        if (limited && Clock::now() > deadline) break;
        body(scorer, worker, (turn * step) % chunks);
        ++done;
      }
      walks += scorer.past_early_exit() - prototype.past_early_exit();
    } catch (...) {
      if (!failed.exchange(true)) failure = std::current_exception();
    }
  };
  const int helpers_wanted =
      static_cast<int>(std::min<size_t>(static_cast<size_t>(threads), chunks)) - 1;
  {
    std::vector<std::jthread> helpers;
    for (int t = 0; t < helpers_wanted; ++t) helpers.emplace_back(work, static_cast<size_t>(t) + 1);
    work(0);
  }  // joins the helpers
  if (failure) std::rethrow_exception(failure);
  return ChunkRun{walks.load(), chunks - done.load()};
}

// The windows with a non-zero score that one worker's column chunks found, chunk after chunk in
// the order it ran them, and their grid rows. One buffer per worker, not per chunk: a chunk's own
// vectors grew from empty, and the threads of a request then took turns at the allocator's lock
// (one heap, heap_tuning.h) hundreds of times a frame. Aligned so that two workers' vectors do
// not share a cache line.
struct alignas(64) WorkerHits {
  std::vector<ScoreWindow> hits;
  std::vector<int> rows;
};

// Where a column chunk's hits lie: [begin, end) of its worker's buffers; worker -1 if the
// deadline left it unscanned.
struct ColumnChunk {
  int worker = -1;
  size_t begin = 0, end = 0;
  long long windows = 0;
  long long walks = 0;
};

// The column scan's hits in grid order, their grid rows, and where each column's hits begin
// (column i: [column_begin[i], column_begin[i + 1])).
struct GridHits {
  std::vector<ScoreWindow> hits;
  std::vector<int> rows;
  std::vector<size_t> column_begin;
};

// Puts the chunks' hits back in grid order (chunk after chunk, each from its worker's buffers)
// and adds the chunks' counters to `stats`, with the columns of chunks never scanned as skipped.
GridHits GatherInGridOrder(const std::vector<ColumnChunk>& scanned,
                           const std::vector<WorkerHits>& found,
                           const std::vector<int>& column_hits, EdgeBoxStats& stats) {
  GridHits out;
  size_t total = 0;
  for (const ColumnChunk& chunk : scanned) total += chunk.end - chunk.begin;
  out.hits.reserve(total);
  out.rows.reserve(total);
  for (size_t c = 0; c < scanned.size(); ++c) {
    const ColumnChunk& chunk = scanned[c];
    if (chunk.worker < 0) {
      const size_t first = c * kColumnsPerChunk;
      stats.columns_skipped +=
          static_cast<long long>(std::min(column_hits.size(), first + kColumnsPerChunk) - first);
      continue;
    }
    stats.windows_visited += chunk.windows;
    stats.windows_past_early_exit += chunk.walks;
    const WorkerHits& from = found[static_cast<size_t>(chunk.worker)];
    const auto first = static_cast<std::ptrdiff_t>(chunk.begin);
    const auto last = static_cast<std::ptrdiff_t>(chunk.end);
    out.hits.insert(out.hits.end(), from.hits.begin() + first, from.hits.begin() + last);
    out.rows.insert(out.rows.end(), from.rows.begin() + first, from.rows.begin() + last);
  }
  out.column_begin.reserve(column_hits.size() + 1);
  out.column_begin.push_back(0);
  for (const int count : column_hits) out.column_begin.push_back(out.column_begin.back() + count);
  stats.windows_nonzero = static_cast<long long>(out.hits.size());
  return out;
}

// Of `candidates` (grid order), all or the refine_limit best by grid score (ties: grid order),
// in grid order.
std::vector<size_t> BestByGridScore(const std::vector<ScoreWindow>& hits,
                                    std::vector<size_t> candidates, int refine_limit) {
  if (refine_limit <= 0 || static_cast<size_t>(refine_limit) >= candidates.size()) {
    return candidates;
  }
  const auto better = [&hits](size_t a, size_t b) {
    return hits[a].score > hits[b].score || (hits[a].score == hits[b].score && a < b);
  };
  std::nth_element(candidates.begin(), candidates.begin() + refine_limit, candidates.end(), better);
  candidates.resize(static_cast<size_t>(refine_limit));
  std::sort(candidates.begin(), candidates.end());
  return candidates;
}

// Indexes (grid order) of the hits whose grid score no grid neighbour of the same shape (one
// stride away in x, y or both) exceeds.
std::vector<size_t> LocalMaxima(const std::vector<ScoreWindow>& hits, const std::vector<int>& rows,
                                const std::vector<size_t>& column_begin,
                                const std::vector<GridColumn>& columns) {
  std::vector<size_t> kept;
  kept.reserve(hits.size() / 4);
  // The hits of a column are in row order, so the hits near row r of a column are found by a
  // cursor that only moves forward as r grows (a binary search per hit and neighbour column
  // cost more than the rest of the selection).
  struct Cursor {
    size_t at = 0, end = 0;
  };
  // Best score among the hits from the cursor on at grid rows [row - 1, row + 1].
  const auto best_near = [&](Cursor& cursor, int row) {
    while (cursor.at < cursor.end && rows[cursor.at] < row - 1) ++cursor.at;
    float best = 0.f;
    for (size_t k = cursor.at; k < cursor.end && rows[k] <= row + 1; ++k) {
      best = std::max(best, hits[k].score);
    }
    return best;
  };
  for (size_t column = 0; column < columns.size(); ++column) {
    const bool left = column > 0 && columns[column - 1].shape == columns[column].shape;
    const bool right =
        column + 1 < columns.size() && columns[column + 1].shape == columns[column].shape;
    Cursor own{column_begin[column], column_begin[column + 1]};
    Cursor before = left ? Cursor{column_begin[column - 1], column_begin[column]} : Cursor{};
    Cursor after = right ? Cursor{column_begin[column + 1], column_begin[column + 2]} : Cursor{};
    for (size_t i = column_begin[column]; i < column_begin[column + 1]; ++i) {
      const int row = rows[i];
      float best = best_near(own, row);
      if (left) best = std::max(best, best_near(before, row));
      if (right) best = std::max(best, best_near(after, row));
      if (hits[i].score >= best) kept.push_back(i);
    }
  }
  return kept;
}

// The grid's columns, one per window shape and column position, and the window tops the size
// filter admits in them.
struct ScanGrid {
  std::vector<WindowShape> shapes;
  std::vector<GridColumn> columns;
  std::vector<RowRanges> shape_tops;  // per shape, for its unclamped columns; empty: no filter
};

// Window tops the size filter admits for a column at x of a shape: from the column's clamped
// width and how far refinement can move the window's sides.
RowRanges AdmittedTops(const BoxScorer& scorer, const EdgeBoxParams& params,
                       const WindowAdmission& admission, int x, const WindowShape& shape) {
  const float refine_ratio = (1.f - params.alpha) / (1.f + params.alpha);
  const int c0 = std::min(x, scorer.width() - 1);
  const int c1 = std::min(x + shape.width, scorer.width() - 1);
  const RefinementSchedule schedule = ScheduleRefinement(shape.height, c1 - c0, refine_ratio);
  const RefinementReach reach =
      params.refine ? RefinementReach{schedule.row_reach, schedule.col_reach} : RefinementReach{};
  return admission.AdmittedTops(c1 - c0 + 1, shape.height + 1, reach, scorer.height());
}

ScanGrid MakeScanGrid(const BoxScorer& scorer, const EdgeBoxParams& params,
                      const WindowAdmission* admission) {
  ScanGrid grid;
  grid.shapes = WindowShapes(scorer.width(), scorer.height(), params);
  for (int s = 0; s < static_cast<int>(grid.shapes.size()); ++s) {
    // Same bounds as the grid definition: the last window may overhang and is clamped.
    const WindowShape& shape = grid.shapes[s];
    const int x_end = scorer.width() - shape.width + shape.stride_x;
    for (int x = 0; x < x_end; x += shape.stride_x) grid.columns.push_back({s, x});
  }
  if (admission != nullptr) {
    for (const WindowShape& shape : grid.shapes) {
      grid.shape_tops.push_back(AdmittedTops(scorer, params, *admission, 0, shape));
    }
  }
  return grid;
}

// Pass 1: scores every grid window (steps 4-6), column chunks on `threads` threads, and returns
// the hits (score at least min_score) in grid order.
GridHits ScanColumns(const BoxScorer& scorer, const EdgeBoxParams& params, const ScanGrid& grid,
                     const WindowAdmission* admission, int threads, EdgeBoxStats& stats) {
  const std::vector<GridColumn>& columns = grid.columns;
  const size_t column_chunks = (columns.size() + kColumnsPerChunk - 1) / kColumnsPerChunk;
  std::vector<ColumnChunk> scanned(column_chunks);
  std::vector<WorkerHits> found(static_cast<size_t>(std::max(1, threads)));
  std::vector<int> column_hits(columns.size(), 0);  // stays 0 for columns never scanned
  const ChunkRun scan = ParallelChunks(
      scorer, column_chunks, threads, params.deadline, [&](BoxScorer& s, size_t worker, size_t c) {
        ColumnChunk& out = scanned[c];
        WorkerHits& own = found[worker];
        out.worker = static_cast<int>(worker);
        out.begin = own.hits.size();
        const size_t end = std::min(columns.size(), (c + 1) * kColumnsPerChunk);
        const long long walks_before = s.past_early_exit();
        for (size_t i = c * kColumnsPerChunk; i < end; ++i) {
          const WindowShape& shape = grid.shapes[columns[i].shape];
          // Tops admitted for this column: the shape's own unless the column is clamped narrower.
          const RowRanges* tops =
              admission != nullptr ? &grid.shape_tops[columns[i].shape] : nullptr;
          RowRanges clamped_tops;
          if (tops != nullptr && columns[i].x + shape.width > s.width() - 1) {
            clamped_tops = AdmittedTops(scorer, params, *admission, columns[i].x, shape);
            tops = &clamped_tops;
          }
          const size_t before = own.hits.size();
          out.windows += s.ScoreColumn(columns[i].x, shape.width, shape.height, shape.stride_y,
                                       tops, /*bar=*/-1.f, own.hits, &own.rows);
          column_hits[i] = static_cast<int>(own.hits.size() - before);
        }
        out.end = own.hits.size();
        out.walks = s.past_early_exit() - walks_before;
      });
  stats.scorings += scan.walks;
  if (scan.skipped > 0) stats.truncated = true;
  return GatherInGridOrder(scanned, found, column_hits, stats);
}

// Pass 2: refinement (step 7) of the best refine_limit local maxima (or every hit), in grid
// order - neighbouring windows share cache lines, which matters more than anything an order by
// score bounds could skip.
void RefineHits(const BoxScorer& scorer, const EdgeBoxParams& params,
                const std::vector<GridColumn>& columns, int threads, GridHits& grid,
                EdgeBoxStats& stats) {
  std::vector<ScoreWindow>& hits = grid.hits;
  // Local maxima first, so that refine_limit picks the best of them.
  std::vector<size_t> chosen;
  if (params.refine_local_maxima) {
    chosen = LocalMaxima(hits, grid.rows, grid.column_begin, columns);
  } else {
    chosen.resize(hits.size());
    std::iota(chosen.begin(), chosen.end(), size_t{0});
  }
  chosen = BestByGridScore(hits, std::move(chosen), params.refine_limit);
  const size_t chunks = (chosen.size() + kRefinementsPerChunk - 1) / kRefinementsPerChunk;
  std::atomic<long long> refined_windows{0};
  const ChunkRun refined =
      ParallelChunks(scorer, chunks, threads, params.deadline, [&](BoxScorer& s, size_t, size_t c) {
        const size_t end = std::min(chosen.size(), (c + 1) * kRefinementsPerChunk);
        for (size_t i = c * kRefinementsPerChunk; i < end; ++i) s.Refine(hits[chosen[i]]);
        refined_windows += static_cast<long long>(end - c * kRefinementsPerChunk);
      });
  stats.scorings += refined.walks;
  stats.windows_refined = refined_windows.load();
  if (refined.skipped > 0) {
    stats.truncated = true;
    stats.refinements_skipped = static_cast<long long>(chosen.size()) - stats.windows_refined;
  }
}

}  // namespace

// One scan of the grid (steps 4-6), refinement (step 7) and NMS (step 8).
std::vector<ScoredBox> ScanWindowGrid(const BoxScorer& scorer, const EdgeBoxParams& params,
                                      EdgeBoxStats& stats, const WindowAdmission* admission) {
  const int threads = ResolveThreadCount(params.threads);
  const ScanGrid grid = MakeScanGrid(scorer, params, admission);
  GridHits hits = ScanColumns(scorer, params, grid, admission, threads, stats);
  if (params.refine) RefineHits(scorer, params, grid.columns, threads, hits, stats);
  std::vector<ScoredBox> boxes;
  boxes.reserve(hits.hits.size());
  for (const ScoreWindow& w : hits.hits) boxes.push_back(ScoredBox{ToBox(w), w.score});
  hits = {};
  return NonMaximumSuppression(std::move(boxes), params.beta, params.max_boxes);
}

}  // namespace tod
