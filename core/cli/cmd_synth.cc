// tod synth --out DIR --train N --test M --seed S [--width 2048 --height 1024]
//           [--obstacles N] [--size-m MIN MAX] [--distance-m MIN MAX]
//           [--horizon-frac F] [--camera-height-m H] [--focal-frac F] [--camera-jitter J]
#include <iostream>
#include <optional>
#include <tuple>
#include <utility>

#include "core/cli/commands.h"
#include "core/synth/synth.h"

namespace tod::cli {

Runner AddSynthCommand(CLI::App& app) {
  struct Args {
    std::string out;
    int train = 20, test = 10, width = 2048, height = 1024;
    std::uint64_t seed = 1;
    std::optional<int> obstacles;
    std::optional<std::pair<double, double>> size_m, distance_m;
    SynthParams camera;  // its camera fields only
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("synth", "write synthetic road scenes in the Lost and Found layout");
  cmd->add_option("--out", args->out, "output dataset directory")->required();
  cmd->add_option("--train", args->train, "training frames")->check(CLI::NonNegativeNumber);
  cmd->add_option("--test", args->test, "test frames")->check(CLI::NonNegativeNumber);
  cmd->add_option("--seed", args->seed, "random seed (same seed, same frames)");
  cmd->add_option("--width", args->width, "frame width")->check(CLI::Range(64, 8192));
  cmd->add_option("--height", args->height, "frame height")->check(CLI::Range(64, 8192));
  // Plain scenes (the demo's: one obstacle of 20-50 cm at 10-25 m) narrow the random ranges.
  cmd->add_option("--obstacles", args->obstacles, "obstacles per frame (default: 1 to 4)")
      ->check(CLI::Range(0, 16));
  cmd->add_option("--size-m", args->size_m, "obstacle size range MIN MAX, metres (0.05 0.6)")
      ->check(CLI::Range(0.01, 5.0));
  cmd->add_option("--distance-m", args->distance_m,
                  "obstacle distance range MIN MAX, metres (5 60)")
      ->check(CLI::Range(1.0, 200.0));
  // Other cameras (issue 48): the horizon's row, the mounting height and the lens; each frame's
  // true camera is written beside its labels (<stem>_camera.json).
  cmd->add_option("--horizon-frac", args->camera.horizon_frac,
                  "horizon row as a share of the height (0.40)")
      ->check(CLI::Range(-0.5, 1.0));
  cmd->add_option("--camera-height-m", args->camera.camera_height_m,
                  "camera height above the road, metres (1.4)")
      ->check(CLI::Range(0.3, 5.0));
  cmd->add_option("--focal-frac", args->camera.focal_frac,
                  "focal length as a share of the width (1.1)")
      ->check(CLI::Range(0.2, 5.0));
  cmd->add_option("--camera-jitter", args->camera.camera_jitter,
                  "per-frame variation of the camera, relative (0.08)")
      ->check(CLI::Range(0.0, 0.5));
  return [args] {
    SynthParams params;
    params.horizon_frac = args->camera.horizon_frac;
    params.camera_height_m = args->camera.camera_height_m;
    params.focal_frac = args->camera.focal_frac;
    params.camera_jitter = args->camera.camera_jitter;
    params.width = args->width;
    params.height = args->height;
    if (args->obstacles) params.min_obstacles = params.max_obstacles = *args->obstacles;
    if (args->size_m) std::tie(params.min_size_m, params.max_size_m) = *args->size_m;
    if (args->distance_m) {
      std::tie(params.min_distance_m, params.max_distance_m) = *args->distance_m;
    }
    if (params.min_size_m > params.max_size_m || params.min_distance_m > params.max_distance_m) {
      return Fail("--size-m and --distance-m take MIN MAX with MIN <= MAX");
    }
    const Status st = WriteSynthDataset(
        args->out, params, args->train, args->test, args->seed, [](int done, int total) {
          if (done % 10 == 0 || done == total)
            std::cerr << "synth: " << done << "/" << total << " frames\n";
        });
    if (!st.ok()) return Fail(st.message());
    std::cout << "wrote " << args->train << " train + " << args->test << " test frames to "
              << args->out << "\n";
    return 0;
  };
}

}  // namespace tod::cli
