// Multilayer (ML) regions (ALGORITHM.md §1): nested rectangles R1 ⊇ ... ⊇ RK, derived offline by
// k-means on the training obstacles' pseudodistance (bottom distance, pixel area), or the
// authors' shipped Lost and Found boxes (preset "laf2020").
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

struct RegionParams {
  int num_layers = 4;  // K
  int restarts = 10;   // k-means++ restarts, lowest SSE kept
  int max_iterations = 300;
  double margin_fraction = 0.1;  // grown on each side, as a fraction of the box size (§1.4)
  std::uint64_t seed = 1;
};

// One training obstacle as k-means sees it.
struct ObstacleFootprint {
  Box box;               // tight box
  long long pixels = 0;  // mask pixel count
};

struct MultilayerRegions {
  int image_width = 0;
  int image_height = 0;
  std::vector<Box> layers;  // paper indexing: layers[0] = R1 (largest) ... layers[K-1] = RK

  int num_layers() const { return static_cast<int>(layers.size()); }
  // n(p): number of layers containing pixel (x, y).
  int LayerCount(int x, int y) const;
  // Row limits of the vertical ranges (§6.1): y_1 > y_2 > ... > y_{K+1}, y_k = bottom row of R_k,
  // y_{K+1} = top row of R_K. V_k = (y_{k+1}, y_k].
  std::vector<int> RangeLimits() const;
  // The same regions for a frame of another size (scaled proportionally).
  MultilayerRegions ScaledTo(int width, int height) const;

  nlohmann::json ToJson() const;
  static Result<MultilayerRegions> FromJson(const nlohmann::json& j);
};

// §1.4: min-max normalised (bottom distance, area), seeded k-means++, clusters ordered near to
// far, R_k = tight box of the union of clusters k..K grown by the margin, clipped, nested.
Result<MultilayerRegions> DeriveMultilayerRegions(const std::vector<ObstacleFootprint>& obstacles,
                                                  int image_width, int image_height,
                                                  const RegionParams& params = {});

// The authors' shipped LAF regions (§1.3), 2048 x 1024.
MultilayerRegions Laf2020Regions();

}  // namespace tod
