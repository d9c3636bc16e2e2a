// Box size filter (ALGORITHM.md §4.3, from the authors' code, not in the paper): a box is kept
// when its centre row lies in one of three bands and its h, w, area fall in that band's ranges
// (with slack 20 * i for band i). Derived from training ground truth; switchable.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "core/base/types.h"

namespace tod {

struct SizeBand {
  double center_y_min = 0, center_y_max = 0;  // open interval
  double h_min = 0, h_max = 0;
  double w_min = 0, w_max = 0;
  double area_min = 0, area_max = 0;
};

struct SizeFilter {
  bool enabled = true;
  std::vector<SizeBand> bands;

  bool Keep(const Box& box) const;
  std::vector<ScoredBox> Apply(const std::vector<ScoredBox>& boxes) const;

  // Recipe of §4.3: bands = [min, max] of training obstacle centre-y split in three equal parts;
  // ranges = per-band min / max of box h, w, area; slack 20 * i.
  static SizeFilter Derive(const std::vector<Box>& training_obstacle_boxes, int num_bands = 3);
  // The LAF numbers shipped with the authors' code, for 2048 x 1024 frames.
  static SizeFilter Laf2020();

  nlohmann::json ToJson() const;
  static SizeFilter FromJson(const nlohmann::json& j);  // throws nlohmann::json::exception
};

}  // namespace tod
