// Obstacles on the road: sampled so their physical size and distance follow the ranges
// (0.05-0.6 m at 5-60 m by default), placed inside the road, and drawn with shading, a contact
// shadow and (in sun) a cast shadow. Every body pixel is labelled with the obstacle's instance.
#pragma once

#include <vector>

#include "core/synth/synth.h"
#include "core/synth/synth_canvas.h"
#include "core/synth/synth_rng.h"
#include "core/synth/synth_scene.h"

namespace tod::synth {

// Random obstacles for one frame: count in [min, max]; each placed on the road, not overlapping
// the others, at least min_obstacle_height_px tall in the image (smaller ones are redrawn; if a
// frame cannot fit one after many tries it gets fewer).
std::vector<SynthObstacleSpec> SampleObstacles(const SynthParams& params, const SceneLayout& layout,
                                               Rng& rng);

// Distance of the obstacle's nearest point (painter's order).
double NearestDistance(const SynthObstacleSpec& spec);

// Draws shadows and body; body pixels get `labels` and Surface::kStanding.
void DrawObstacle(Canvas& canvas, const SceneLayout& layout, const SynthObstacleSpec& spec,
                  Labels labels, Rng& rng);

}  // namespace tod::synth
