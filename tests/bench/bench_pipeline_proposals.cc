// OLP proposal work on the occlusion maps a trained model really produces (the proposals stage
// is the largest part of a frame), measured side by side in one run for three configurations:
//   paper        every scoring window refined; the size filter runs on the output only
//   +admission   windows that cannot end as a box the size filter keeps are not scored
//   +local-max   and only the grid's local maxima are refined, at most refine_limit of them per
//                region (the model's own setting)
// and a digest of the returned boxes and scores (a speed-up that claims exactness must keep it).
// Per configuration: median milliseconds per frame over all regions (scoring + refinement +
// NMS, one core), grid windows scored, walks, windows refined, and the boxes that pass the size
// filter. Then, for the model's own configuration, the same per region. Asserts nothing.
//   bench_pipeline_proposals MODEL_DIR [FRAMES=3] [WIDTH=2048 HEIGHT=1024]
// Frames are synthetic scenes (seeded, as in bench_pipeline_frame).
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/pipeline/model_bundle.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/proposals/window_admission.h"
#include "core/synth/synth.h"

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Config {
  std::string name;
  bool admission = false;
  bool local_maxima = false;
  int refine_limit = 0;
};

struct Totals {
  tod::EdgeBoxStats stats;  // summed over frames
  long long kept = 0;       // boxes through the size filter, summed over frames
  std::uint64_t digest = 14695981039346656037ull;  // FNV-1a of every returned box and score
  std::vector<double> ms;  // per frame (config totals) or per frame for one region
};

void Add(Totals& t, const tod::EdgeBoxStats& s, long long kept) {
  t.stats.windows_visited += s.windows_visited;
  t.stats.windows_past_early_exit += s.windows_past_early_exit;
  t.stats.windows_refined += s.windows_refined;
  t.stats.scorings += s.scorings;
  t.kept += kept;
}

// One region scored once under one configuration: its time, counts and the boxes through the
// size filter (null: no filter); every returned box and score is folded into `digest`.
struct RegionRun {
  double ms = 0.0;
  tod::EdgeBoxStats stats;
  long long kept = 0;
};

RegionRun ScoreRegion(const cv::Mat1f& map, const tod::EdgeBoxParams& params,
                      const tod::WindowAdmission* admission, const tod::SizeFilter* filter,
                      const tod::Box& region, std::uint64_t& digest) {
  RegionRun run;
  const auto start = std::chrono::steady_clock::now();
  const std::vector<tod::ScoredBox> boxes = tod::ScoreEdgeBoxes(map, params, &run.stats, admission);
  run.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  for (const tod::ScoredBox& b : boxes) {
    for (const int v : {b.box.x, b.box.y, b.box.w, b.box.h, static_cast<int>(b.score * 1e7f)})
      digest = (digest ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
  }
  for (tod::ScoredBox b : boxes) {
    b.box.y += region.y;
    b.box.x += region.x;
    run.kept += filter == nullptr || filter->Keep(b.box);
  }
  return run;
}

// The configurations side by side: median ms, speed-up over the paper's, counts per frame.
void PrintConfigTable(const std::vector<Config>& configs, const std::vector<Totals>& totals,
                      const tod::SynthParams& synth, int frames) {
  std::printf("frame %dx%d, %d frames, one core; counts per frame (mean), times median\n",
              synth.width, synth.height, frames);
  std::printf(
      "| configuration | ms | vs paper | windows scored | walks | refined | kept boxes | digest |\n"
      "|---|---|---|---|---|---|---|---|\n");
  const double paper_ms = Median(totals[0].ms);
  for (size_t c = 0; c < configs.size(); ++c) {
    const Totals& t = totals[c];
    const double ms = Median(t.ms);
    std::printf("| %s | %.1f | %.2fx | %lld | %lld | %lld | %lld | %016llx |\n",
                configs[c].name.c_str(), ms, ms > 0 ? paper_ms / ms : 0.0,
                t.stats.windows_visited / frames, t.stats.scorings / frames,
                t.stats.windows_refined / frames, t.kept / frames,
                static_cast<unsigned long long>(t.digest));
  }
}

// The model's own configuration region by region.
void PrintRegionTable(const std::string& name, const std::vector<Totals>& region_totals,
                      const std::vector<cv::Size>& region_sizes, bool multistride, int frames) {
  const int layers = static_cast<int>(region_totals.size());
  std::printf("\nper region, %s\n", name.c_str());
  std::printf(
      "| region | map | stride factor | windows scored | walks | refined | kept boxes | ms |\n"
      "|---|---|---|---|---|---|---|---|\n");
  for (int k = 0; k < layers; ++k) {
    const Totals& r = region_totals[static_cast<size_t>(k)];
    const cv::Size size = region_sizes[static_cast<size_t>(k)];
    std::printf("| R%d | %dx%d | %.2f | %lld | %lld | %lld | %lld | %.1f |\n", k + 1, size.width,
                size.height,
                multistride ? static_cast<double>(layers - k) / static_cast<double>(layers) : 1.0,
                r.stats.windows_visited / frames, r.stats.scorings / frames,
                r.stats.windows_refined / frames, r.kept / frames, Median(r.ms));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s MODEL_DIR [FRAMES] [WIDTH HEIGHT]\n", argv[0]);
    return 2;
  }
  const int frames = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  tod::SynthParams synth;
  if (argc > 4) {
    synth.width = std::atoi(argv[3]);
    synth.height = std::atoi(argv[4]);
  }
  cv::setNumThreads(0);
  auto bundle = tod::LoadModelBundle(argv[1]);
  if (!bundle.ok()) {
    std::fprintf(stderr, "%s\n", bundle.status().ToString().c_str());
    return 1;
  }
  const tod::FrameGeometry geometry = tod::GeometryForFrame(*bundle, synth.width, synth.height);
  const tod::SizeFilter& filter = geometry.size_filter;
  const bool filtered = bundle->params.size_filter && filter.enabled;
  const int layers = geometry.regions.num_layers();
  const int limit = bundle->params.boxes.refine_limit;
  const std::vector<Config> configs = {
      {"paper", false, false, 0},
      {"+admission", true, false, 0},
      {"+local-max (limit " + std::to_string(limit) + ")", true, true, limit}};
  std::vector<Totals> config_totals(configs.size());
  std::vector<Totals> region_totals(static_cast<size_t>(layers));  // the model's configuration
  std::vector<cv::Size> region_sizes(static_cast<size_t>(layers));
  for (int f = 0; f < frames; ++f) {
    const tod::Sample frame = tod::GenerateSynthFrame(synth, 1000 + static_cast<unsigned>(f), "b");
    const tod::Result<tod::OcclusionEdges> computed = tod::ComputeOcclusionEdges(
        frame.image, geometry.regions, *bundle->edges, &bundle->occlusion, bundle->params, true);
    if (!computed.ok()) {
      std::cerr << computed.status().ToString() << "\n";
      return 1;
    }
    const tod::OcclusionEdges& oaocc = *computed;
    std::vector<double> frame_ms(configs.size(), 0.0);
    for (int k = 0; k < layers; ++k) {
      const cv::Mat1f map = tod::NormaliseToMax(tod::RegionEdgeMap(oaocc, geometry.regions, k));
      const tod::Box region = tod::Intersect(geometry.regions.layers[k], oaocc.r1);
      region_sizes[static_cast<size_t>(k)] = map.size();
      tod::EdgeBoxParams params = bundle->params.boxes;
      params.threads = 1;
      params.stride_factor = bundle->params.multistride
                                 ? static_cast<float>(layers - k) / static_cast<float>(layers)
                                 : 1.f;
      const tod::WindowAdmission admission(filter, region.y);
      for (size_t c = 0; c < configs.size(); ++c) {
        params.refine_local_maxima = configs[c].local_maxima;
        params.refine_limit = configs[c].refine_limit;
        const RegionRun run =
            ScoreRegion(map, params, configs[c].admission && filtered ? &admission : nullptr,
                        filtered ? &filter : nullptr, region, config_totals[c].digest);
        frame_ms[c] += run.ms;
        Add(config_totals[c], run.stats, run.kept);
        if (c + 1 == configs.size()) {
          Totals& r = region_totals[static_cast<size_t>(k)];
          Add(r, run.stats, run.kept);
          r.ms.push_back(run.ms);
        }
      }
    }
    for (size_t c = 0; c < configs.size(); ++c) config_totals[c].ms.push_back(frame_ms[c]);
  }
  PrintConfigTable(configs, config_totals, synth, frames);
  PrintRegionTable(configs.back().name, region_totals, region_sizes, bundle->params.multistride,
                   frames);
  return 0;
}
