// Ground textures evaluated on the road plane (world metres, not pixels), so asphalt grain,
// paving joints and wear shrink with distance exactly like the obstacles do. Octaves finer than
// about two pixels are faded out (the camera would average them), which avoids aliasing far away.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "core/synth/synth_camera.h"
#include "core/synth/synth_canvas.h"
#include "core/synth/synth_rng.h"

namespace tod::synth {

// Periodic (256 cells) value noise in [-1, 1] with smooth interpolation.
class ValueNoise {
 public:
  explicit ValueNoise(Rng& rng);
  float At(double x, double z) const;
  // Octaves of a fractal sum from `coarsest_m` down (each half the size and `persistence` times
  // the amplitude), with the weight of each octave at a given pixel footprint.
  struct Octaves {
    static constexpr int kMax = 4;
    int count = 0;
    double inv_cell[kMax] = {};
    float weight[kMax] = {};  // amplitude * visibility / total amplitude
  };
  static Octaves OctavesFor(double coarsest_m, int octaves, float persistence,
                            double metres_per_pixel);
  float Fractal(double x, double z, const Octaves& octaves) const;

 private:
  static constexpr int kPeriod = 256;
  std::vector<float> table_;
};

// How one ground surface looks.
struct GroundMaterial {
  cv::Vec3f base{110, 110, 110};  // BGR
  float blotch_amp = 0.10f;       // large-scale stains and wear (cells of ~2 m)
  float grain_amp = 0.10f;        // aggregate grain (cells of a few cm)
  double blotch_cell_m = 2.5;
  double grain_cell_m = 0.08;
  // Paving: rectangular tiles in a running bond, per-tile tone jitter and dark joints.
  bool tiles = false;
  double tile_across_m = 0.2;
  double tile_along_m = 0.1;
  float tile_jitter = 0.06f;
  float joint_darkness = 0.35f;
  // Road only: darker wheel tracks at these lateral offsets from the road centre.
  std::vector<double> wheel_tracks_m;
  float wheel_track_darkness = 0.0f;
};

struct GroundMaterials {
  GroundMaterial road, sidewalk, verge, far_ground;
};

// Shades every ground pixel of the canvas (per its Surface) with its material. `road_centre_at`
// gives the road's centre line X at each distance (wheel tracks follow curves).
void ShadeGround(Canvas& canvas, const PinholeCamera& camera, const GroundMaterials& materials,
                 const ValueNoise& noise, std::uint64_t tile_seed,
                 const std::function<double(double)>& road_centre_at);

}  // namespace tod::synth
