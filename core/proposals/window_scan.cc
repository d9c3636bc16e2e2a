#include "core/proposals/window_scan.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <numeric>
#include <thread>

#include "core/proposals/window_grid.h"

namespace tod {
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

// Runs body(scorer, chunk) for chunk = 0 .. chunks - 1 on `threads` threads (the caller's
// included), each with its own copy of the scorer; returns the walks the copies ran. Which
// thread runs which chunk varies, so bodies write only to their chunk's own output.
template <typename Body>
long long ParallelChunks(const BoxScorer& prototype, size_t chunks, int threads, Body body) {
  std::atomic<size_t> next_chunk{0};
  std::atomic<long long> walks{0};
  std::atomic<bool> failed{false};
  std::exception_ptr failure;
  const auto work = [&]() {
    try {
      BoxScorer scorer(prototype);  // own walk scratch, shared map tables
      for (size_t c = next_chunk++; c < chunks && !failed; c = next_chunk++) body(scorer, c);
      walks += scorer.past_early_exit() - prototype.past_early_exit();
    } catch (...) {
      if (!failed.exchange(true)) failure = std::current_exception();
    }
  };
  const int helpers_wanted =
      static_cast<int>(std::min<size_t>(static_cast<size_t>(threads), chunks)) - 1;
  {
    std::vector<std::jthread> helpers;
    for (int t = 0; t < helpers_wanted; ++t) helpers.emplace_back(work);
    work();
  }  // joins the helpers
  if (failure) std::rethrow_exception(failure);
  return walks.load();
}

struct ColumnChunk {
  std::vector<ScoreWindow> hits;  // windows with a non-zero score, grid order
  long long windows = 0;
  long long walks = 0;
};

// Indexes of the windows to refine: all, or the refine_limit best by grid score (ties: grid
// order), in grid order.
std::vector<size_t> WindowsToRefine(const std::vector<ScoreWindow>& hits, int refine_limit) {
  std::vector<size_t> chosen(hits.size());
  std::iota(chosen.begin(), chosen.end(), size_t{0});
  if (refine_limit <= 0 || static_cast<size_t>(refine_limit) >= hits.size()) return chosen;
  const auto better = [&hits](size_t a, size_t b) {
    return hits[a].score > hits[b].score || (hits[a].score == hits[b].score && a < b);
  };
  std::nth_element(chosen.begin(), chosen.begin() + refine_limit, chosen.end(), better);
  chosen.resize(static_cast<size_t>(refine_limit));
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

}  // namespace

int ResolveThreadCount(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

std::vector<ScoredBox> ScanWindowGrid(const BoxScorer& scorer, const EdgeBoxParams& params,
                                      EdgeBoxStats& stats) {
  const int threads = ResolveThreadCount(params.threads);
  const std::vector<WindowShape> shapes = WindowShapes(scorer.width(), scorer.height(), params);
  std::vector<GridColumn> columns;
  for (int s = 0; s < static_cast<int>(shapes.size()); ++s) {
    // Same bounds as the grid definition: the last window may overhang and is clamped.
    const int x_end = scorer.width() - shapes[s].width + shapes[s].stride_x;
    for (int x = 0; x < x_end; x += shapes[s].stride_x) columns.push_back({s, x});
  }

  // Pass 1: score every grid window (steps 4-6).
  const size_t column_chunks = (columns.size() + kColumnsPerChunk - 1) / kColumnsPerChunk;
  std::vector<ColumnChunk> scanned(column_chunks);
  stats.scorings += ParallelChunks(scorer, column_chunks, threads, [&](BoxScorer& s, size_t c) {
    ColumnChunk& out = scanned[c];
    const size_t end = std::min(columns.size(), (c + 1) * kColumnsPerChunk);
    const long long walks_before = s.past_early_exit();
    for (size_t i = c * kColumnsPerChunk; i < end; ++i) {
      const WindowShape& shape = shapes[columns[i].shape];
      out.windows += WindowPositionCount(s.height(), shape.height, shape.stride_y);
      s.ScoreColumn(columns[i].x, shape.width, shape.height, shape.stride_y, out.hits);
    }
    out.walks = s.past_early_exit() - walks_before;
  });
  std::vector<ScoreWindow> hits;
  for (ColumnChunk& chunk : scanned) {
    stats.windows_visited += chunk.windows;
    stats.windows_past_early_exit += chunk.walks;
    hits.insert(hits.end(), chunk.hits.begin(), chunk.hits.end());
    chunk.hits = {};
  }
  stats.windows_nonzero = static_cast<long long>(hits.size());

  // Pass 2: refinement (step 7) in grid order - neighbouring windows share cache lines, which
  // matters more than anything an order by score bounds could skip - then NMS (step 8).
  if (params.refine) {
    const std::vector<size_t> chosen = WindowsToRefine(hits, params.refine_limit);
    const size_t chunks = (chosen.size() + kRefinementsPerChunk - 1) / kRefinementsPerChunk;
    stats.scorings += ParallelChunks(scorer, chunks, threads, [&](BoxScorer& s, size_t c) {
      const size_t end = std::min(chosen.size(), (c + 1) * kRefinementsPerChunk);
      for (size_t i = c * kRefinementsPerChunk; i < end; ++i) s.Refine(hits[chosen[i]]);
    });
    stats.windows_refined = static_cast<long long>(chosen.size());
  }
  std::vector<ScoredBox> boxes;
  boxes.reserve(hits.size());
  for (const ScoreWindow& w : hits) boxes.push_back(ScoredBox{ToBox(w), w.score});
  hits = {};
  return NonMaximumSuppression(std::move(boxes), params.beta, params.max_boxes);
}

}  // namespace tod
