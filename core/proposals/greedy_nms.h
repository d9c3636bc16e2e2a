// Greedy NMS fed one box at a time in final order (ALGORITHM.md §4.2.8): keeps a box if its IoU
// with every kept box is <= the threshold, up to max_boxes. NonMaximumSuppression sorts the boxes
// and feeds them; an incremental caller can feed boxes whose order it knows.
#pragma once

#include <utility>
#include <vector>

#include "core/base/types.h"

namespace tod {

class GreedyNms {
 public:
  // The top-left corners of all boxes that will be offered lie in [min_x, max_x] x
  // [min_y, max_y] (sizes the position grid; correctness does not depend on it).
  GreedyNms(float iou_threshold, int max_boxes, int min_x, int min_y, int max_x, int max_y);

  // Offers the next box in order (score descending); returns whether it was kept.
  bool Offer(const ScoredBox& box);
  bool full() const { return static_cast<int>(kept_.size()) >= max_boxes_; }
  const std::vector<ScoredBox>& kept() const { return kept_; }
  std::vector<ScoredBox> TakeKept() { return std::move(kept_); }

 private:
  struct Entry {
    Box box;
    int next = -1;  // next entry in the same cell
  };
  struct Grid {
    int cell_shift = 1;  // side in pixels = 2^cell_shift
    int cols = 0, rows = 0;
    std::vector<int> head;  // first entry per cell (column-major), -1 = none
    int CellX(long long offset) const;
    int CellY(long long offset) const;
  };
  bool Suppressed(const Box& candidate) const;
  void Add(const Box& kept);
  int BinOf(const Box& b) const;
  Grid MakeGrid(int bin) const;

  float threshold_;
  int max_boxes_;
  double log_step_ = 0.0;
  double radius_factor_ = 0.0;
  int min_x_ = 0, min_y_ = 0, max_x_ = 0, max_y_ = 0;
  std::vector<Grid> grids_;  // per log-area bin; empty = flat mode (threshold outside (0, 1))
  std::vector<Entry> entries_;
  std::vector<Box> flat_;
  std::vector<ScoredBox> kept_;
};

}  // namespace tod
