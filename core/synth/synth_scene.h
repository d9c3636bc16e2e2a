// Scene layout and the static parts of a synthetic frame: sky, ground surfaces (road between
// curbs, sidewalks, verges), markings, hard negatives on the road and background clutter. The
// obstacles are drawn by synth_obstacles.
#pragma once

#include <functional>
#include <vector>

#include "core/synth/synth.h"
#include "core/synth/synth_camera.h"
#include "core/synth/synth_canvas.h"
#include "core/synth/synth_rng.h"
#include "core/synth/synth_shapes.h"
#include "core/synth/synth_textures.h"

namespace tod::synth {

// The road: a constant-width strip whose centre line may bend (X_c(z) = offset + k z^2 / 2, a
// parabola approximating a gentle curve) and which ends at `end_m`, where background blocks it.
struct RoadGeometry {
  double width_m = 8.0;
  double centre_offset_m = 0.0;
  double curvature_per_m = 0.0;
  double end_m = 80.0;

  double CentreAt(double z) const { return centre_offset_m + 0.5 * curvature_per_m * z * z; }
  double LeftEdgeAt(double z) const { return CentreAt(z) - 0.5 * width_m; }
  double RightEdgeAt(double z) const { return CentreAt(z) + 0.5 * width_m; }
};

// What lies beside the road on one side, from the road edge outwards.
struct RoadSide {
  double curb_height_m = 0.12;  // 0: no curb
  double sidewalk_m = 2.5;      // 0: none
  double verge_m = 3.0;
  double OuterOffset() const { return sidewalk_m + verge_m; }
};

struct SceneLayout {
  cv::Size size;
  PinholeCamera camera;
  RoadGeometry road;
  RoadSide left, right;
  Lighting light;
  GroundMaterials materials;
  cv::Vec3f sky_top, sky_horizon;
  double near_m = 4.0;  // nearest ground distance drawn (just below the image bottom)

  // Sample distances from near_m to road.end_m, denser near the camera.
  std::vector<double> DepthSamples(int count) const;
};

// Draws with `rng` exactly; the same rng state gives the same scene.
SceneLayout SampleLayout(const SynthParams& params, Rng& rng);

// Sky, ground surfaces with their textures, curbs; writes the road labels (free space).
void DrawSkyAndGround(Canvas& canvas, const SceneLayout& layout, Rng& rng);
// Lane lines, edge lines, crossings, parking bays: paint on the road (still free space).
void DrawRoadMarkings(Canvas& canvas, const SceneLayout& layout, Rng& rng);
// Hard negatives: repair patches, manhole covers and drains, cracks, scrawls, stains, shadows.
void DrawHardNegatives(Canvas& canvas, const SceneLayout& layout, Rng& rng);

// Something standing on the ground, drawn far to near (painter's order) together with the
// obstacles; nearest_m is the distance of its nearest point.
struct StandingItem {
  double nearest_m = 0;
  std::function<void(Canvas&)> draw;
};
// Skyline at the road's end, facades, trees, poles, parked cars, fences, bollards.
std::vector<StandingItem> SampleClutter(const SceneLayout& layout, Rng& rng);

}  // namespace tod::synth
