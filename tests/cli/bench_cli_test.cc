// `tod bench` end to end on two small frames of the tiny fixture (tests/make_fixture.sh): it runs
// and its JSON has the keys issue 11 fixes. Times are only checked for consistency, never
// against a bound: speed is measured by running the benchmark, not by tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/run_command.h"
#include "tests/test_env.h"

namespace {
namespace fs = std::filesystem;

using tod::testing_env::CommandResult;
using tod::testing_env::RunCommand;

const std::vector<std::string> kStages = {"decode",     "edges",    "superpixels", "occlusion",
                                          "proposals",  "features", "regression",  "map",
                                          "encode_map", "total"};

class BenchCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tod_ = tod::testing_env::BinDir() + "/tod";
    model_ = tod::testing_env::TestModel();
    ASSERT_TRUE(fs::exists(tod_)) << "TOD_BIN_DIR not set or tod not built";
    ASSERT_TRUE(fs::exists(fs::path(model_) / "manifest.json"))
        << "fixture model missing: " << model_;
    out_ = fs::temp_directory_path() /
           ("tod_bench_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(out_);
    frames_ = out_ / "frames";
    // Two of the fixture's test frames, one in a subdirectory (the search is recursive), beside
    // a file that is not a frame.
    std::vector<fs::path> images;
    const fs::path test_frames = fs::path(tod::testing_env::TestData()) / "leftImg8bit" / "test";
    for (const auto& e : fs::recursive_directory_iterator(test_frames))
      if (e.path().extension() == ".png") images.push_back(e.path());
    ASSERT_GE(images.size(), 2u);
    std::sort(images.begin(), images.end());
    fs::create_directories(frames_ / "sub");
    fs::copy_file(images[0], frames_ / "a.png");
    fs::copy_file(images[1], frames_ / "sub" / "b.png");
    std::ofstream(frames_ / "notes.txt") << "not a frame\n";
  }
  void TearDown() override { fs::remove_all(out_); }

  CommandResult Bench(const std::string& extra) const {
    return RunCommand(tod_ + " bench --frames " + frames_.string() + " --model " + model_ + " " +
                      extra);
  }

  std::string tod_, model_;
  fs::path out_;
  fs::path frames_;
};

TEST_F(BenchCliTest, TwoFramesGiveTheContractJsonAndTables) {
  const fs::path json_path = out_ / "bench.json";
  const CommandResult run = Bench("--json " + json_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("peak RSS"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("EdgeBoxes"), std::string::npos) << run.output;

  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frames"], 2);
  EXPECT_EQ(j["threads_per_request"], 1);
  EXPECT_NE(run.output.find("1 thread per request"), std::string::npos) << run.output;
  ASSERT_TRUE(j["stages_ms"].is_object());
  for (const std::string& stage : kStages) {
    ASSERT_TRUE(j["stages_ms"].contains(stage)) << stage;
    const nlohmann::json& s = j["stages_ms"][stage];
    for (const char* key : {"median", "p90", "max"}) ASSERT_TRUE(s[key].is_number()) << stage;
    EXPECT_GE(s["median"].get<double>(), 0) << stage;
    EXPECT_LE(s["median"].get<double>(), s["p90"].get<double>()) << stage;
    EXPECT_LE(s["p90"].get<double>(), s["max"].get<double>()) << stage;
  }
  EXPECT_GT(j["stages_ms"]["total"]["median"].get<double>(), 0);
  EXPECT_DOUBLE_EQ(j["proposals_ms"]["median"].get<double>(),
                   j["stages_ms"]["proposals"]["median"].get<double>());
  EXPECT_GT(j["opencv_edgeboxes_ms"]["median"].get<double>(), 0);
  EXPECT_GT(j["peak_rss_mb"].get<double>(), 0);
  // tod bench allocates from one heap, as tod_server does, unless the operator set the arenas.
  if (std::getenv("MALLOC_ARENA_MAX") == nullptr) {
    EXPECT_EQ(j["shared_heap"], true);
  }

  ASSERT_EQ(j["per_frame"].size(), 2u);
  for (const nlohmann::json& frame : j["per_frame"]) {
    EXPECT_EQ(frame["width"], 640);
    EXPECT_GT(frame["windows_scored"].get<long long>(), 0);
    EXPECT_GT(frame["edge_groups"].get<long long>(), 0);
    EXPECT_GT(frame["proposals"].get<long long>(), 0);
    // total is the wall clock from decode to the encoded map, so it holds every stage.
    double stages = 0;
    for (const std::string& stage : kStages)
      if (stage != "total") stages += frame["stages_ms"][stage].get<double>();
    EXPECT_GE(frame["stages_ms"]["total"].get<double>() + 1e-6, stages);
  }
}

TEST_F(BenchCliTest, LimitTakesTheFirstFramesByPath) {
  const fs::path json_path = out_ / "one.json";
  const CommandResult run = Bench("--limit 1 --threads 2 --json " + json_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frames"], 1);
  EXPECT_EQ(fs::path(j["per_frame"][0]["frame"].get<std::string>()).filename(), "a.png");
}

// A file that is named like a frame but cannot be decoded is skipped and listed; the frames
// around it keep their own records (each frame's record has its slot from the start), in path
// order, with one frame per thread as with one thread.
TEST_F(BenchCliTest, AnUndecodableFrameIsSkippedAndTheOthersKeepTheirRecords) {
  std::ofstream(frames_ / "b_broken.png") << "not a PNG";
  const fs::path json_path = out_ / "skip.json";
  const CommandResult run = Bench("--threads 2 --json " + json_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("skipped " + (frames_ / "b_broken.png").string()), std::string::npos)
      << run.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frames"], 2);
  EXPECT_EQ(j["skipped_frames"]["count"], 1);
  ASSERT_EQ(j["per_frame"].size(), 2u);
  EXPECT_EQ(fs::path(j["per_frame"][0]["frame"].get<std::string>()).filename(), "a.png");
  EXPECT_EQ(fs::path(j["per_frame"][1]["frame"].get<std::string>()).filename(), "b.png");
  for (const nlohmann::json& frame : j["per_frame"]) EXPECT_GT(frame["stages_ms"]["total"], 0);
}

// --frame-budget-ms and --threads-per-request, as tod_server has them: a budget no frame can
// meet degrades every frame's occlusion map (its forest stops after the first piece of trees)
// and proposals, and bench and detect both say so.
TEST_F(BenchCliTest, FrameBudgetDegradationIsReportedByBenchAndDetect) {
  const fs::path json_path = out_ / "budget.json";
  const CommandResult run =
      Bench("--frame-budget-ms 1 --threads-per-request 2 --json " + json_path.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("frame budget 1 ms (2 frames degraded)"), std::string::npos)
      << run.output;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["frame_budget_ms"], 1);
  EXPECT_EQ(j["threads_per_request"], 2);
  EXPECT_NE(run.output.find("2 threads per request"), std::string::npos) << run.output;
  EXPECT_EQ(j["degraded_frames"], 2);
  for (const nlohmann::json& frame : j["per_frame"])
    EXPECT_EQ(frame["degraded_stages"], nlohmann::json({"occlusion", "proposals"})) << frame.dump();

  const fs::path detect_out = out_ / "detect";
  const CommandResult detect =
      RunCommand(tod_ + " detect --model " + model_ + " --out " + detect_out.string() +
                 " --frame-budget-ms 1 " + (frames_ / "a.png").string());
  ASSERT_EQ(detect.exit_code, 0) << detect.output;
  std::ifstream detect_json(detect_out / "a.json");
  const nlohmann::json d = nlohmann::json::parse(detect_json);
  EXPECT_EQ(d["degraded"], true) << d.dump();
  EXPECT_EQ(d["degraded_stages"], nlohmann::json({"occlusion", "proposals"})) << d.dump();
  EXPECT_EQ(d["map_kind"], "normalized");

  // The calibrated map: named in the JSON; its peak is the calibrated score of the best box, not
  // the 1 every normalised map has (unless the model is certain).
  const CommandResult calibrated =
      RunCommand(tod_ + " detect --model " + model_ + " --out " + detect_out.string() +
                 " --map-kind calibrated " + (frames_ / "a.png").string());
  ASSERT_EQ(calibrated.exit_code, 0) << calibrated.output;
  std::ifstream calibrated_json(detect_out / "a.json");
  EXPECT_EQ(nlohmann::json::parse(calibrated_json)["map_kind"], "calibrated");
  const CommandResult unknown_kind =
      RunCommand(tod_ + " detect --model " + model_ + " --out " + detect_out.string() +
                 " --map-kind sum " + (frames_ / "a.png").string());
  EXPECT_NE(unknown_kind.exit_code, 0) << unknown_kind.output;

  const CommandResult refused = Bench("--frame-budget-ms -5");
  EXPECT_NE(refused.exit_code, 0) << refused.output;
}

TEST_F(BenchCliTest, ADirectoryWithoutFramesIsAnError) {
  const fs::path empty = out_ / "empty";
  fs::create_directories(empty);
  const CommandResult run =
      RunCommand(tod_ + " bench --frames " + empty.string() + " --model " + model_);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no PNG, JPEG or WebP frame"), std::string::npos) << run.output;
}

}  // namespace
