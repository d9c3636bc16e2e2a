// Synthetic road scenes in the Lost and Found layout (issue 2): a calibrated pinhole camera over
// a road plane, so an obstacle's size and image row follow from its distance. For tests, demos
// and the default model only; the method must not be tuned to this generator.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "core/base/status.h"
#include "core/base/types.h"

namespace tod {

struct SynthParams {
  int width = 2048;
  int height = 1024;
  // Camera: horizon row as a fraction of the height, camera height above the road (m),
  // focal length in pixels as a fraction of the width.
  double horizon_frac = 0.40;
  double camera_height_m = 1.4;
  double focal_frac = 1.1;
  // Obstacles: count per frame, physical size and distance ranges.
  int min_obstacles = 1;
  int max_obstacles = 4;
  double min_size_m = 0.05;
  double max_size_m = 0.6;
  double min_distance_m = 5.0;
  double max_distance_m = 60.0;
};

// One frame, deterministic for (params, seed): image plus full ground truth.
Sample GenerateSynthFrame(const SynthParams& params, std::uint64_t seed, const std::string& name);

// Writes `train_count` + `test_count` frames to `out_dir` in the LAF layout (scene folders,
// _leftImg8bit.png, _gtCoarse_labelIds.png, _gtCoarse_instanceIds.png).
Status WriteSynthDataset(const std::string& out_dir, const SynthParams& params, int train_count,
                         int test_count, std::uint64_t seed,
                         const std::function<void(int done, int total)>& progress = {});

}  // namespace tod
