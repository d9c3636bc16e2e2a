// OLP proposal work per region on the occlusion maps a trained model really produces (the
// proposals stage is most of a frame's time): for each region R1..RK, the map size, the MS
// stride factor, the windows of the grid, how many ran the boundary-affinity walk, how many
// scored, all walks with refinement, the boxes out, and the median milliseconds of the grid
// alone and of grid + refinement + NMS. Prints a table; asserts nothing.
//   bench_pipeline_proposals MODEL_DIR [FRAMES=3] [WIDTH=2048 HEIGHT=1024] [REFINE_LIMIT=0]
// Frames are synthetic scenes (seeded, as in bench_pipeline_frame); one core.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/data/synth.h"
#include "core/pipeline/model_bundle.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/proposals/window_admission.h"

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

template <typename F>
double TimeMs(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

struct RegionRow {
  int width = 0, height = 0;
  float stride_factor = 0.f;
  tod::EdgeBoxStats stats;  // summed over frames
  std::vector<double> grid_ms, full_ms;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MODEL_DIR [FRAMES] [WIDTH HEIGHT] [REFINE_LIMIT]\n", argv[0]);
    return 2;
  }
  const int frames = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  tod::SynthParams synth;
  if (argc > 4) {
    synth.width = std::atoi(argv[3]);
    synth.height = std::atoi(argv[4]);
  }
  const int refine_limit = argc > 5 ? std::atoi(argv[5]) : 0;
  cv::setNumThreads(0);
  auto bundle = tod::LoadModelBundle(argv[1]);
  if (!bundle.ok()) {
    std::fprintf(stderr, "%s\n", bundle.status().ToString().c_str());
    return 1;
  }
  const tod::FrameGeometry geometry = tod::GeometryForFrame(*bundle, synth.width, synth.height);
  const int layers = geometry.regions.num_layers();
  std::vector<RegionRow> rows(static_cast<size_t>(layers));
  for (int f = 0; f < frames; ++f) {
    const tod::Sample frame = tod::GenerateSynthFrame(synth, 1000 + static_cast<unsigned>(f), "b");
    const tod::OcclusionEdges oaocc =
        tod::ComputeOcclusionEdges(frame.image, geometry.regions, *bundle->edges,
                                   &bundle->occlusion, bundle->params.superpixels, true);
    for (int k = 0; k < layers; ++k) {
      const cv::Mat1f map = tod::NormaliseToMax(tod::RegionEdgeMap(oaocc, geometry.regions, k));
      tod::EdgeBoxParams params = bundle->params.boxes;
      params.threads = 1;
      params.refine_limit = refine_limit;
      params.stride_factor = bundle->params.multistride
                                 ? static_cast<float>(layers - k) / static_cast<float>(layers)
                                 : 1.f;
      RegionRow& row = rows[static_cast<size_t>(k)];
      row.width = map.cols;
      row.height = map.rows;
      row.stride_factor = params.stride_factor;
      tod::EdgeBoxParams grid_only = params;
      grid_only.refine = false;
      const tod::Box region = tod::Intersect(geometry.regions.layers[k], oaocc.r1);
      std::optional<tod::WindowAdmission> admission;
      if (bundle->params.size_filter) admission.emplace(geometry.size_filter, region.y);
      const tod::WindowAdmission* admit = admission ? &*admission : nullptr;
      row.grid_ms.push_back(TimeMs([&] { tod::ScoreEdgeBoxes(map, grid_only, nullptr, admit); }));
      tod::EdgeBoxStats stats;
      row.full_ms.push_back(TimeMs([&] { tod::ScoreEdgeBoxes(map, params, &stats, admit); }));
      row.stats.windows_visited += stats.windows_visited;
      row.stats.windows_past_early_exit += stats.windows_past_early_exit;
      row.stats.windows_nonzero += stats.windows_nonzero;
      row.stats.scorings += stats.scorings;
      row.stats.boxes_out += stats.boxes_out;
    }
  }
  std::printf("frame %dx%d, %d frames, refine_limit %d, one core; counts are per frame (mean)\n",
              synth.width, synth.height, frames, refine_limit);
  std::printf(
      "| region | map | stride x | windows | walks | non-zero | walks w/ refine | boxes | grid ms "
      "| grid+refine+NMS ms |\n|---|---|---|---|---|---|---|---|---|---|\n");
  double grid_total = 0, full_total = 0;
  for (int k = 0; k < layers; ++k) {
    const RegionRow& r = rows[static_cast<size_t>(k)];
    const double g = Median(r.grid_ms), t = Median(r.full_ms);
    grid_total += g;
    full_total += t;
    std::printf("| R%d | %dx%d | %.2f | %lld | %lld | %lld | %lld | %lld | %.1f | %.1f |\n", k + 1,
                r.width, r.height, r.stride_factor, r.stats.windows_visited / frames,
                r.stats.windows_past_early_exit / frames, r.stats.windows_nonzero / frames,
                r.stats.scorings / frames, r.stats.boxes_out / frames, g, t);
  }
  std::printf("| all | | | | | | | | %.1f | %.1f |\n", grid_total, full_total);
  return 0;
}
