// tod synth --out DIR --train N --test M --seed S [--width 2048 --height 1024]
#include <iostream>

#include "core/cli/commands.h"
#include "core/synth/synth.h"

namespace tod::cli {

Runner AddSynthCommand(CLI::App& app) {
  struct Args {
    std::string out;
    int train = 20, test = 10, width = 2048, height = 1024;
    std::uint64_t seed = 1;
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
  return [args] {
    SynthParams params;
    params.width = args->width;
    params.height = args->height;
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
