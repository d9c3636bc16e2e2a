// `tod train` and `tod eval --format modd2` end to end on a small set of marine scenes in the
// exact MODDv2 layout (water below a horizon line, small floating objects, large ones on the
// horizon), written by the test.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/synth/modd2_synth.h"
#include "tests/run_command.h"
#include "tests/test_env.h"

namespace {
namespace fs = std::filesystem;

std::pair<int, std::string> Shell(const std::string& command) {
  const tod::testing_env::CommandResult run = tod::testing_env::RunCommand(command);
  return {run.exit_code, run.output};
}

TEST(Modd2Cli, TrainAndEvalOnMarineScenes) {
  const fs::path dir = fs::temp_directory_path() / ("tod_modd2_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  // 4 sequences (1 train, 3 test by the synthetic split), 8 frames each, 480 x 360.
  ASSERT_TRUE(tod::WriteModd2SynthDataset((dir / "modd2").string(), 4, 8, 480, 360, 11).ok());
  const std::string tod = tod::testing_env::BinDir() + "/tod";
  auto [code, out] = Shell(tod + " train --data " + (dir / "modd2").string() +
                           " --format modd2 --out " + (dir / "model").string() +
                           " --seed 3 --trees 20 --no-eval --paper local_maxima_refinement");
  ASSERT_EQ(code, 0) << out;
  std::ifstream manifest_in(dir / "model" / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(manifest_in);
  // Regions and size filter come from the marine training split at its own resolution.
  EXPECT_EQ(manifest["regions"]["image_width"], 480);
  EXPECT_EQ(manifest["regions"]["image_height"], 360);
  EXPECT_EQ(manifest["training"]["format"], "modd2");
  // --paper local_maxima_refinement: the paper's refinement of every scoring window, recorded with
  // the model.
  EXPECT_EQ(manifest["params"]["boxes"]["refine_local_maxima"], false);
  EXPECT_EQ(manifest["params"]["boxes"]["refine_limit"], 0);

  std::tie(code, out) =
      Shell(tod + " eval --data " + (dir / "modd2").string() + " --format modd2 --model " +
            (dir / "model").string() + " --json " + (dir / "eval.json").string());
  ASSERT_EQ(code, 0) << out;
  std::ifstream eval_in(dir / "eval.json");
  const nlohmann::json eval = nlohmann::json::parse(eval_in);
  EXPECT_EQ(eval["frames"], 24);
  EXPECT_GT(eval["instances"].get<int>(), 10);
  EXPECT_TRUE(eval["regression"]["BP+Fusion@4"]["tpr_at_fpr"].contains("0.030"));
  // Auto-detection of the layout finds MODDv2 without --format.
  std::tie(code, out) = Shell(tod + " eval --data " + (dir / "modd2").string() + " --model " +
                              (dir / "model").string() + " --max-frames 2");
  EXPECT_EQ(code, 0) << out;
  fs::remove_all(dir);
}

}  // namespace
