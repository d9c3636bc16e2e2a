// `tod train|eval|analyse --format masks` as a user of the obstacle benchmarks runs them: a masks
// dataset (images/ + labels_masks/, {0, 1, 255}) is written from the CTest fixture's synthetic
// frames, with JPEG and WebP frames, both mask file names, void and a split file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "core/pipeline/model_bundle.h"
#include "tests/run_command.h"
#include "tests/test_env.h"

namespace {
namespace fs = std::filesystem;

using tod::testing_env::CommandResult;
using tod::testing_env::RunCommand;

class MasksCliTest : public ::testing::Test {
 protected:
  // One dataset for the whole suite (training is the slow part).
  static void SetUpTestSuite() {
    root_ =
        new fs::path(fs::temp_directory_path() / ("tod_masks_cli_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_ / "images");
    fs::create_directories(*root_ / "labels_masks");
    std::ofstream split(*root_ / "split.txt");
    int index = 0;
    const fs::path data(tod::testing_env::TestData());
    for (const char* part : {"train", "test"}) {
      std::vector<fs::path> images;
      for (const auto& e : fs::recursive_directory_iterator(data / "leftImg8bit" / part))
        if (e.path().extension() == ".png") images.push_back(e.path());
      std::sort(images.begin(), images.end());
      for (const fs::path& image : images) {
        const std::string stem = image.filename().string().substr(
            0, image.filename().string().size() - std::string("_leftImg8bit.png").size());
        const fs::path ids_path = data / "gtCoarse" / part / image.parent_path().filename() /
                                  (stem + "_gtCoarse_instanceIds.png");
        const cv::Mat ids = cv::imread(ids_path.string(), cv::IMREAD_UNCHANGED);
        const cv::Mat bgr = cv::imread(image.string(), cv::IMREAD_COLOR);
        if (ids.empty() || bgr.empty()) continue;
        cv::Mat1b mask(ids.size(), uchar{0});
        mask.setTo(1, ids > 1000);
        mask.rowRange(mask.rows - 8, mask.rows).setTo(255);  // a void "hood"
        const std::string name = std::to_string(index);
        const char* extension = index % 3 == 0 ? ".jpg" : index % 3 == 1 ? ".webp" : ".png";
        cv::imwrite((*root_ / "images" / (name + extension)).string(), bgr);
        const std::string mask_name = index % 2 ? name + "_labels_semantic.png" : name + ".png";
        cv::imwrite((*root_ / "labels_masks" / mask_name).string(), mask);
        split << part << " " << name << "\n";
        ++index;
      }
    }
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
  }

  void SetUp() override {
    tod_ = tod::testing_env::BinDir() + "/tod";
    ASSERT_TRUE(fs::exists(tod_));
    out_ = *root_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(out_);
  }
  std::string Root() const { return root_->string(); }
  std::string Train(const std::string& model, const std::string& extra = "") const {
    return tod_ + " train --data " + Root() + " --format masks --out " + model +
           " --trees 10 --classifier-frames 6 --no-eval --threads 2 " + extra;
  }

  static nlohmann::json Manifest(const std::string& model) {
    std::ifstream in(fs::path(model) / "manifest.json");
    return nlohmann::json::parse(in);
  }

  // `tod detect` on `image` with a copy of `model` (out_/name) whose manifest `edit` changed;
  // its output goes to out_/detect_<name>.
  CommandResult DetectForged(const std::string& model, const std::string& name,
                             const std::function<void(nlohmann::json&)>& edit,
                             const std::string& image) const {
    const fs::path forged = out_ / name;
    fs::copy(model, forged, fs::copy_options::recursive);
    nlohmann::json manifest = Manifest(forged.string());
    edit(manifest);
    std::ofstream(forged / "manifest.json") << manifest.dump(2);
    return RunCommand(tod_ + " detect --model " + forged.string() + " --out " +
                      (out_ / ("detect_" + name)).string() + " " + image);
  }

  static fs::path* root_;
  std::string tod_;
  fs::path out_;
};
fs::path* MasksCliTest::root_ = nullptr;

TEST_F(MasksCliTest, TrainAndEvalOnMaskBenchmarkLayout) {
  const std::string model = (out_ / "model").string();
  const CommandResult train = RunCommand(Train(model));
  ASSERT_EQ(train.exit_code, 0) << train.output;
  EXPECT_NE(train.output.find("peak RSS"), std::string::npos) << train.output;
  std::ifstream manifest_in(fs::path(model) / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(manifest_in);
  EXPECT_EQ(manifest["training"]["format"], "masks");
  for (const char* part : {"edges", "occlusion", "ordr", "obdr", "calibration"})
    EXPECT_EQ(manifest["training"]["parts"][part]["trained"], true) << part;
  EXPECT_EQ(manifest["training"]["parts"]["ordr"]["hard_negatives"], "mined");
  EXPECT_EQ(manifest["training"]["parts"]["edges"]["trees"], 16);
  EXPECT_EQ(manifest["training"]["parts"]["occlusion"]["trees"], 400);
  EXPECT_EQ(manifest["params"]["edge_screening"]["trees"], 0);  // off: every tree on every cell
  // The occlusion classifier's early exit, on in a new bundle: 25 trees, bound 0.05.
  EXPECT_EQ(manifest["params"]["occlusion_screening"]["trees"], 25);
  EXPECT_FLOAT_EQ(manifest["params"]["occlusion_screening"]["final_at_most"].get<float>(), 0.05f);
  EXPECT_FLOAT_EQ(manifest["params"]["boxes"]["max_wide_aspect_ratio"].get<float>(), 10.f);
  const nlohmann::json& size_filter = manifest["training"]["parts"]["size_filter"];
  EXPECT_EQ(size_filter["recipe"], "ground_plane") << size_filter.dump();
  EXPECT_TRUE(size_filter["horizon_y"].is_number()) << size_filter.dump();
  EXPECT_EQ(manifest["size_filter"]["bands"].size(), 8u);
  EXPECT_TRUE(manifest["params"]["obstacle_calibration"]["fitted"].get<bool>());
  EXPECT_LT(manifest["params"]["prior_correction"]["occlusion_odds"].get<double>(), 1.0);

  const std::string json = (out_ / "eval.json").string();
  const CommandResult eval = RunCommand(tod_ + " eval --data " + Root() + " --split test --model " +
                                        model + " --json " + json + " --threads 2");
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_NE(eval.output.find("no road label"), std::string::npos) << eval.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_GT(j["frames"].get<int>(), 0);
  EXPECT_GT(j["instances"].get<int>(), 0);
  EXPECT_TRUE(j["regression"]["BP+Fusion@4"].contains("ap"));
  // The calibrated map is evaluated beside the paper's, since the model has a calibration.
  ASSERT_TRUE(j["calibrated_map"].is_object()) << j.dump();
  EXPECT_EQ(j["calibrated_map"]["boxes"], "BP+Fusion@4");
  EXPECT_TRUE(j["calibrated_map"]["tpr_at_fpr"].contains("0.020"));
  EXPECT_TRUE(j["calibrated_map"].contains("ap"));
  EXPECT_NE(eval.output.find("BP+Fusion@4 cal"), std::string::npos) << eval.output;
  for (const char* key : {"false_alarms_per_frame", "false_alarms_per_obstacle_free_frame",
                          "obstacle_free_frames", "instances_found", "calibration_flat"})
    EXPECT_TRUE(j["obstacles"].contains(key)) << key;

  const std::string analysis_json = (out_ / "analysis.json").string();
  const CommandResult analyse =
      RunCommand(tod_ + " analyse --data " + Root() + " --split test --model " + model +
                 " --threads 2 --json " + analysis_json);
  ASSERT_EQ(analyse.exit_code, 0) << analyse.output;
  EXPECT_NE(analyse.output.find("Where obstacles are lost"), std::string::npos);
  EXPECT_NE(analyse.output.find("Pixel AP of the paper's map"), std::string::npos)
      << analyse.output;
  std::ifstream analysis_in(analysis_json);
  const nlohmann::json a = nlohmann::json::parse(analysis_in);
  // The served scoring is the detector's own: the same proposals, map and pooling as the AP
  // `tod eval` reports for BP+Fusion@4 on the same split.
  EXPECT_NEAR(a["pixel_ap"]["served"].get<double>(),
              j["regression"]["BP+Fusion@4"]["ap"].get<double>(), 1e-9)
      << a["pixel_ap"].dump();
  for (const char* key : {"false_boxes_removed", "perfect_scores"})
    EXPECT_TRUE(a["pixel_ap"][key].is_number()) << key;
  ASSERT_FALSE(a["frames"].empty());
  for (const nlohmann::json& frame : a["frames"]) {
    EXPECT_GE(frame["best_false_box_score"].get<double>(), 0.0) << frame.dump();
    EXPECT_GE(frame["false_boxes_above"].get<long long>(), 0) << frame.dump();
  }
}

// By default the regressors train a second time on negatives the first round scored highest;
// --paper hard_negative_mining gives the paper's single round. The manifest says which, and the
// forests differ (same seed).
TEST_F(MasksCliTest, HardNegativeMiningByDefaultOneRoundOnRequest) {
  const std::string plain = (out_ / "plain").string(), mined = (out_ / "mined").string();
  const CommandResult plain_run = RunCommand(Train(plain, "--paper hard_negative_mining"));
  ASSERT_EQ(plain_run.exit_code, 0) << plain_run.output;
  EXPECT_EQ(plain_run.output.find("mining hard negatives"), std::string::npos);
  const nlohmann::json p = Manifest(plain);
  for (const char* part : {"ordr", "obdr"})
    EXPECT_EQ(p["training"]["parts"][part]["hard_negatives"], "objectness") << part;
  const CommandResult mined_run = RunCommand(Train(mined));
  ASSERT_EQ(mined_run.exit_code, 0) << mined_run.output;
  EXPECT_NE(mined_run.output.find("mining hard negatives"), std::string::npos) << mined_run.output;
  const nlohmann::json m = Manifest(mined);
  for (const char* part : {"ordr", "obdr"}) {
    EXPECT_EQ(m["training"]["parts"][part]["hard_negatives"], "mined") << part;
    EXPECT_EQ(m["training"]["parts"][part]["trained"], true) << part;
    EXPECT_NE(m["files"][std::string(part) + ".bin"]["fnv1a64"],
              p["files"][std::string(part) + ".bin"]["fnv1a64"])
        << part;
  }
  EXPECT_TRUE(m["training"]["seconds"].contains("hard_negatives"));
}

// The classifiers' tree counts are choices the manifest records, and two paper switches reach it:
// the occlusion classifier without its early exit, the paper's window grid. The options measured
// and removed are refused as unknown, and their keys keep their one value. Out of range is
// refused before any work.
TEST_F(MasksCliTest, ForestSizesAndPaperSwitchesReachTheManifest) {
  const std::string model = (out_ / "trees").string();
  const CommandResult run = RunCommand(Train(
      model,
      "--edge-trees 4 --occlusion-trees 12 --paper occlusion_early_exit --paper wide_windows"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json manifest = Manifest(model);
  for (const char* regressor : {"ordr", "obdr"}) {
    const nlohmann::json& part = manifest["training"]["parts"][regressor];
    EXPECT_EQ(part["negative_bags"], 1) << regressor;
    EXPECT_EQ(part["pasted_copies"], 0) << regressor;
    EXPECT_EQ(part["mtry"], 6) << regressor;
    EXPECT_EQ(part["min_leaf"], 5) << regressor;
    EXPECT_EQ(part["hard_fraction"], 0.2) << regressor;
    EXPECT_EQ(part["trees"], 10) << regressor;
  }
  const auto bundle = tod::LoadModelBundle(model);
  ASSERT_TRUE(bundle.ok()) << bundle.status().message();
  EXPECT_EQ(bundle->ordr.num_trees(), 10);
  EXPECT_EQ(bundle->obdr.num_trees(), 10);
  EXPECT_EQ(manifest["params"]["superpixels"]["strip_rows"], 0);
  EXPECT_FLOAT_EQ(manifest["params"]["boxes"]["max_wide_aspect_ratio"].get<float>(), 0.f);
  EXPECT_EQ(manifest["params"]["occlusion_screening"]["trees"], 0);
  EXPECT_EQ(manifest["training"]["parts"]["edges"]["trees"], 4);
  EXPECT_EQ(manifest["training"]["parts"]["occlusion"]["trees"], 12);
  EXPECT_EQ(manifest["training"]["parts"]["edges"]["negatives_per_positive"], 1.0);
  EXPECT_EQ(manifest["training"]["parts"]["occlusion"]["negatives_per_positive"], 4);
  // The regressors' negatives per frame and range: the paper's 17 (ORDR) and 25 (OBDR).
  EXPECT_EQ(manifest["training"]["parts"]["ordr"]["negatives_per_range"],
            nlohmann::json({17, 17, 17, 17}));
  EXPECT_EQ(manifest["training"]["parts"]["obdr"]["negatives_per_range"],
            nlohmann::json({25, 25, 25, 25}));
  for (const char* flag :
       {"--edge-trees 0", "--occlusion-trees 0", "--trees 0", "--paper everything",
        "--negative-bags 2", "--paste-obstacles 2", "--orientation-entropy-feature",
        "--fold-layout alternate", "--no-map-shares", "--refine-all"}) {
    const CommandResult wrong = RunCommand(Train((out_ / "wrong").string(), flag));
    EXPECT_NE(wrong.exit_code, 0) << flag;
    EXPECT_NE(wrong.output.find(std::string(flag).substr(0, std::string(flag).find(' '))),
              std::string::npos)
        << wrong.output;
    EXPECT_FALSE(fs::exists(out_ / "wrong" / "manifest.json"));
  }
}

// `tod train --help` lists what training on one's own data needs, at most 25 options, and names
// every paper switch with a line of its own.
TEST_F(MasksCliTest, TrainHelpIsShortAndNamesThePaperSwitches) {
  const CommandResult help = RunCommand(tod_ + " train --help");
  ASSERT_EQ(help.exit_code, 0) << help.output;
  std::istringstream lines(help.output);
  int options = 0;
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("  -", 0) == 0 && line.rfind("  -h,--help", 0) != 0) ++options;
  EXPECT_GT(options, 10) << help.output;
  EXPECT_LE(options, 25) << help.output;
  for (const char* name :
       {"prior_correction", "size_filter", "local_maxima_refinement", "wide_windows",
        "out_of_fold_maps", "hard_negative_mining", "truth_box_positives", "box_size_features",
        "vertical_edge_feature", "road_surround_feature", "map_isolation", "superpixel_shares",
        "occlusion_early_exit"})
    EXPECT_NE(help.output.find(std::string(name) + ": "), std::string::npos) << name;
}

// Proposal features 10, 12, 13 over the ground plane (the default) or the image's size (--paper
// box_size_features): the manifest keeps the choice and the horizon it divides by (the
// ground-plane prior's), and the bundle runs. The occlusion classifier's sizes stay the paper's
// pixels either way.
TEST_F(MasksCliTest, GroundPlaneFeaturesAreAChoiceAndRecorded) {
  const std::string key = "box_features";
  for (const std::string choice : {"paper", "ground_plane"}) {
    const std::string model = (out_ / ("box_" + choice)).string();
    const bool ground = choice == "ground_plane";
    const CommandResult run = RunCommand(Train(model, ground ? "" : "--paper box_size_features"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json manifest = Manifest(model);
    EXPECT_EQ(manifest["params"][key]["ground_plane_size"], ground) << choice;
    EXPECT_EQ(manifest["training"]["parts"][key]["size"], choice) << choice;
    EXPECT_EQ(manifest["params"]["occlusion_features"]["ground_plane_size"], false);
    EXPECT_EQ(manifest["training"]["parts"]["occlusion_features"]["size"], "paper");
    if (ground) {
      EXPECT_EQ(manifest["params"][key]["horizon_y"],
                manifest["training"]["parts"]["size_filter"]["horizon_y"]);
      EXPECT_NE(run.output.find(key + ": sizes over the rows below row"), std::string::npos)
          << run.output;
    }
    // The bundle runs: detect reads the choice back from the manifest.
    const CommandResult detect = RunCommand(tod_ + " detect --model " + model + " --out " +
                                            (out_ / ("detect_box" + choice)).string() + " " +
                                            (*root_ / "images" / "2.png").string());
    EXPECT_EQ(detect.exit_code, 0) << detect.output;
  }
}

// --paper size_filter restores the authors' per-band extremes (three bands); the manifest names
// the recipe, and an unknown switch is refused before any work.
TEST_F(MasksCliTest, SizeFilterRecipeIsAChoiceAndRecorded) {
  const std::string model = (out_ / "bands").string();
  const CommandResult run = RunCommand(Train(model, "--paper size_filter"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output.find("size filter: horizon at row"), std::string::npos) << run.output;
  std::ifstream in(fs::path(model) / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(in);
  EXPECT_EQ(manifest["training"]["parts"]["size_filter"]["recipe"], "bands");
  EXPECT_EQ(manifest["size_filter"]["bands"].size(), 3u);
  const CommandResult wrong =
      RunCommand(Train((out_ / "wrong").string(), "--paper size_filter_everything"));
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_NE(wrong.output.find("--paper"), std::string::npos) << wrong.output;
  EXPECT_FALSE(fs::exists(out_ / "wrong" / "manifest.json"));
}

// By default each classifier also gets a copy per fold, and every frame's maps for the next part
// come from the other fold's copy (folds of consecutive frames); --paper out_of_fold_maps trains
// on the final classifiers' maps. The manifest says which, and the parts differ (same seed).
TEST_F(MasksCliTest, OutOfFoldMapsByDefaultInSampleOnRequest) {
  const std::string stacked = (out_ / "stacked").string(), plain = (out_ / "plain").string();
  const CommandResult stacked_run = RunCommand(Train(stacked));
  ASSERT_EQ(stacked_run.exit_code, 0) << stacked_run.output;
  EXPECT_NE(stacked_run.output.find("occlusion classifier of fold 1"), std::string::npos)
      << stacked_run.output;
  const CommandResult plain_run = RunCommand(Train(plain, "--paper out_of_fold_maps"));
  ASSERT_EQ(plain_run.exit_code, 0) << plain_run.output;
  EXPECT_EQ(plain_run.output.find("of fold"), std::string::npos) << plain_run.output;
  const nlohmann::json p = Manifest(plain), m = Manifest(stacked);
  EXPECT_EQ(p["training"]["parts"]["occlusion"]["edge_maps"], "in_sample");
  EXPECT_EQ(m["training"]["parts"]["occlusion"]["edge_maps"], "out_of_fold");
  for (const char* part : {"ordr", "obdr"}) {
    EXPECT_EQ(p["training"]["parts"][part]["maps"], "in_sample") << part;
    EXPECT_EQ(m["training"]["parts"][part]["maps"], "out_of_fold") << part;
  }
  for (const char* part : {"occlusion", "ordr", "obdr", "calibration"})
    EXPECT_EQ(m["training"]["parts"][part]["fold_layout"], "blocks") << part;
  // The shipped edge classifier is the same; what it feeds is trained differently.
  EXPECT_EQ(m["files"]["edges.bin"]["fnv1a64"], p["files"]["edges.bin"]["fnv1a64"]);
  for (const char* file : {"occlusion.bin", "ordr.bin"})
    EXPECT_NE(m["files"][file]["fnv1a64"], p["files"][file]["fnv1a64"]) << file;
}

// The map's isolation exponent (box_isolation.h) is fitted by default on the calibration's
// out-of-fold maps: the manifest lists every candidate with its AP and the winner, which is the
// exponent the bundle's parameters carry. --paper map_isolation keeps the paper's map. The same
// out-of-fold components fit the obstacle calibration, which is held monotone (flat, never
// inverted) and refused on load when a manifest inverts it.
TEST_F(MasksCliTest, MapIsolationAndCalibrationFittedOutOfFoldPaperMapOnRequest) {
  const std::string fitted = (out_ / "fitted").string(), paper = (out_ / "paper").string();
  const CommandResult fitted_run = RunCommand(Train(fitted));
  ASSERT_EQ(fitted_run.exit_code, 0) << fitted_run.output;
  const CommandResult paper_run = RunCommand(Train(paper, "--paper map_isolation"));
  ASSERT_EQ(paper_run.exit_code, 0) << paper_run.output;

  const nlohmann::json f = Manifest(fitted);
  const nlohmann::json& part = f["training"]["parts"]["map_isolation"];
  EXPECT_EQ(part["trained"], true);
  EXPECT_EQ(part["fit"], true);
  ASSERT_EQ(part["candidates"].size(), 6u) << part;
  double best_ap = -1, best_exponent = -1;
  for (const nlohmann::json& c : part["candidates"])
    if (c["ap"].is_number() && c["ap"].get<double>() > best_ap)
      best_ap = c["ap"].get<double>(), best_exponent = c["exponent"].get<double>();
  ASSERT_GE(best_exponent, 0) << part;
  EXPECT_DOUBLE_EQ(part["exponent"].get<double>(), best_exponent);
  EXPECT_DOUBLE_EQ(f["params"]["probability_map"]["isolation"]["exponent"].get<double>(),
                   best_exponent);

  const nlohmann::json p = Manifest(paper);
  EXPECT_EQ(p["training"]["parts"]["map_isolation"]["fit"], false);
  EXPECT_EQ(p["training"]["parts"]["map_isolation"]["candidates"].size(), 1u);
  EXPECT_EQ(p["params"]["probability_map"]["isolation"]["exponent"].get<double>(), 0.0);
  // The regressors do not depend on the map: the same forests either way.
  EXPECT_EQ(f["files"]["ordr.bin"]["fnv1a64"], p["files"]["ordr.bin"]["fnv1a64"]);

  // `tod detect` serves the map of the bundle's exponent: the same bundle with the paper's map
  // and with isolation to the 4th power give different maps of the same frame.
  const std::string image = Root() + "/images/2.png";  // a frame of the set, with obstacles
  cv::Mat maps[2];
  for (const int exponent : {0, 4}) {
    const std::string name = "exponent_" + std::to_string(exponent);
    const CommandResult detect = DetectForged(
        paper, name,
        [exponent](nlohmann::json& m) {
          m["params"]["probability_map"]["isolation"]["exponent"] = exponent;
        },
        image);
    ASSERT_EQ(detect.exit_code, 0) << detect.output;
    const fs::path out = out_ / ("detect_" + name);
    maps[exponent == 0 ? 0 : 1] = cv::imread((out / "2_prob.png").string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(maps[exponent == 0 ? 0 : 1].empty());
  }
  EXPECT_GT(cv::norm(maps[0], maps[1], cv::NORM_L1), 0.0);

  // The obstacle calibration says whether it was held flat; a bundle whose calibration would
  // make a score fall as its evidence rises is refused by name, not served inverted.
  EXPECT_TRUE(p["training"]["parts"]["calibration"]["flat"].is_boolean())
      << p["training"]["parts"]["calibration"].dump();
  const CommandResult inverted = DetectForged(
      paper, "inverted_calibration",
      [](nlohmann::json& m) { m["params"]["obstacle_calibration"]["slope"] = -3.7; }, image);
  EXPECT_NE(inverted.exit_code, 0);
  EXPECT_NE(inverted.output.find("obstacle_calibration.slope"), std::string::npos)
      << inverted.output;
  // A flat calibration is served, and `tod eval` says so in its text and JSON.
  const fs::path flat = out_ / "flat_calibration";
  fs::copy(paper, flat, fs::copy_options::recursive);
  nlohmann::json flat_manifest = Manifest(flat.string());
  flat_manifest["params"]["obstacle_calibration"]["slope"] = 0.0;
  flat_manifest["params"]["obstacle_calibration"]["flat"] = true;
  std::ofstream(flat / "manifest.json") << flat_manifest.dump(2);
  const std::string flat_json = (out_ / "flat_eval.json").string();
  const CommandResult flat_eval =
      RunCommand(tod_ + " eval --data " + Root() + " --split test --model " + flat.string() +
                 " --json " + flat_json + " --threads 2");
  ASSERT_EQ(flat_eval.exit_code, 0) << flat_eval.output;
  EXPECT_NE(flat_eval.output.find("obstacle calibration is flat"), std::string::npos)
      << flat_eval.output;
  std::ifstream flat_in(flat_json);
  EXPECT_EQ(nlohmann::json::parse(flat_in)["obstacles"]["calibration_flat"], true);
}

// The map weighs boxes by superpixel shares by default (probability_map.h); --paper
// superpixel_shares paints whole boxes, as the paper. `tod detect` serves the map the bundle's
// parameters name, and `tod eval` measures it.
TEST_F(MasksCliTest, MapSharesAreOnByDefaultWholeBoxesOnRequest) {
  const std::string shares = (out_ / "shares").string(), whole = (out_ / "whole").string();
  const CommandResult shares_run = RunCommand(Train(shares, "--paper map_isolation"));
  ASSERT_EQ(shares_run.exit_code, 0) << shares_run.output;
  const CommandResult whole_run =
      RunCommand(Train(whole, "--paper map_isolation --paper superpixel_shares"));
  ASSERT_EQ(whole_run.exit_code, 0) << whole_run.output;
  EXPECT_EQ(Manifest(shares)["params"]["probability_map"]["superpixel_shares"], true);
  EXPECT_EQ(Manifest(whole)["params"]["probability_map"]["superpixel_shares"], false);
  // The map does not change what is learned: the same forests either way.
  EXPECT_EQ(Manifest(shares)["files"]["ordr.bin"]["fnv1a64"],
            Manifest(whole)["files"]["ordr.bin"]["fnv1a64"]);
  const std::string image = Root() + "/images/2.png";  // a frame of the set, with obstacles
  cv::Mat maps[2];
  nlohmann::json obstacles[2];
  for (int k = 0; k < 2; ++k) {
    const fs::path out = out_ / (k == 0 ? "detect_shares" : "detect_whole");
    const CommandResult detect =
        RunCommand(tod_ + " detect --min-obstacle-score 0 --model " + (k == 0 ? shares : whole) +
                   " --out " + out.string() + " " + image);
    ASSERT_EQ(detect.exit_code, 0) << detect.output;
    maps[k] = cv::imread((out / "2_prob.png").string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(maps[k].empty());
    std::ifstream json(out / "2.json");
    obstacles[k] = nlohmann::json::parse(json)["obstacles"];
  }
  EXPECT_GT(cv::norm(maps[0], maps[1], cv::NORM_L1), 0.0);
  // The obstacle list stays the whole-box map's (ObstacleComponentsMap), with the same
  // calibration: the same obstacles and scores from either bundle.
  EXPECT_FALSE(obstacles[0].empty());
  EXPECT_EQ(obstacles[0], obstacles[1]);
}

// Two datasets trained together: the folds cut each into runs of its own (training_folds.h), and
// the manifest names both.
TEST_F(MasksCliTest, AddDataTrainsOnBothDatasetsWithFoldsInEach) {
  const std::string model = (out_ / "two").string();
  const CommandResult run = RunCommand(Train(model, "--add-data " + Root()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json m = Manifest(model);
  ASSERT_TRUE(m["training"]["data"].is_array());
  EXPECT_EQ(m["training"]["data"].size(), 2u);
  EXPECT_EQ(m["training"]["parts"]["ordr"]["fold_layout"], "blocks");
  EXPECT_EQ(m["training"]["parts"]["ordr"]["maps"], "out_of_fold");
}

TEST_F(MasksCliTest, BadFrameFailsTheRunOrIsSkippedAndCounted) {
  // A copy of the dataset with one corrupt test image.
  const fs::path copy = out_ / "data";
  fs::create_directories(copy);
  fs::copy(*root_ / "images", copy / "images", fs::copy_options::recursive);
  fs::copy(*root_ / "labels_masks", copy / "labels_masks", fs::copy_options::recursive);
  fs::copy(*root_ / "split.txt", copy / "split.txt");
  std::string victim;
  for (const auto& e : fs::directory_iterator(copy / "images"))
    if (e.path().stem() == "20" || victim.empty()) victim = e.path().string();
  std::ofstream(victim, std::ios::trunc) << "not an image";
  const std::string stem = fs::path(victim).stem().string();

  const std::string model = (out_ / "model").string();
  const CommandResult failed =
      RunCommand(tod_ + " train --data " + copy.string() + " --split all --out " + model +
                 " --trees 5 --classifier-frames 4 --no-eval");
  EXPECT_NE(failed.exit_code, 0);
  EXPECT_NE(failed.output.find("frame " + stem), std::string::npos) << failed.output;
  EXPECT_FALSE(fs::exists(model));

  const CommandResult skipped =
      RunCommand(tod_ + " train --data " + copy.string() + " --split all --out " + model +
                 " --trees 5 --classifier-frames 4 --no-eval --on-bad-frame skip --threads 2"
                 " --paper out_of_fold_maps");  // 2 classifier frames a fold: too few for copies
  ASSERT_EQ(skipped.exit_code, 0) << skipped.output;
  EXPECT_NE(skipped.output.find("skipped frame " + stem), std::string::npos) << skipped.output;
  std::ifstream in(fs::path(model) / "manifest.json");
  const nlohmann::json m = nlohmann::json::parse(in);
  EXPECT_EQ(m["training"]["skipped_frames"]["count"], 1);
}

}  // namespace

namespace {

// Proposal features 21 and 22 (the vertical edge share, the surround unlike the road): `tod
// train` adds them by default and records them, --paper vertical_edge_feature --paper
// road_surround_feature keep the paper's 20; both bundles detect, with different scores,
// and a manifest that claims another feature set than its forests is refused when loaded.
TEST_F(MasksCliTest, OurFeaturesByDefaultPaperFeaturesOnRequest) {
  const std::string with = (out_ / "with").string(), paper = (out_ / "paper").string();
  const CommandResult with_run = RunCommand(Train(with, "--paper map_isolation"));
  ASSERT_EQ(with_run.exit_code, 0) << with_run.output;
  const CommandResult paper_run = RunCommand(Train(
      paper, "--paper map_isolation --paper vertical_edge_feature --paper road_surround_feature"));
  ASSERT_EQ(paper_run.exit_code, 0) << paper_run.output;
  for (const char* feature : {"vertical_edge_feature", "road_surround_feature"}) {
    EXPECT_EQ(Manifest(with)["params"][feature], true) << feature;
    EXPECT_EQ(Manifest(paper)["params"][feature], false) << feature;
  }
  for (const char* regressor : {"ordr", "obdr"}) {
    EXPECT_EQ(Manifest(with)["training"]["parts"][regressor]["features"], 22) << regressor;
    EXPECT_EQ(Manifest(paper)["training"]["parts"][regressor]["features"], 20) << regressor;
  }
  // The edge and occlusion classifiers do not see the proposals' features.
  EXPECT_EQ(Manifest(with)["files"]["occlusion.bin"]["fnv1a64"],
            Manifest(paper)["files"]["occlusion.bin"]["fnv1a64"]);

  const std::string image = Root() + "/images/2.png";
  nlohmann::json proposals[2];
  for (int k = 0; k < 2; ++k) {
    const fs::path out = out_ / (k == 0 ? "detect_with" : "detect_paper");
    const CommandResult detect = RunCommand(tod_ + " detect --model " + (k == 0 ? with : paper) +
                                            " --out " + out.string() + " " + image);
    ASSERT_EQ(detect.exit_code, 0) << detect.output;
    std::ifstream json(out / "2.json");
    proposals[k] = nlohmann::json::parse(json)["proposals"];
    ASSERT_FALSE(proposals[k].empty());
  }
  EXPECT_NE(proposals[0], proposals[1]);

  // The paper bundle's manifest made to claim the 21st feature: its 20-feature forests are
  // refused by name, not read shifted.
  const CommandResult refused = DetectForged(
      paper, "forged", [](nlohmann::json& m) { m["params"]["vertical_edge_feature"] = true; },
      image);
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("must take 21 features"), std::string::npos) << refused.output;
  // And the default bundle's manifest without the road feature: its 22-feature forests too.
  const CommandResult no_road = DetectForged(
      with, "forged_road", [](nlohmann::json& m) { m["params"]["road_surround_feature"] = false; },
      image);
  EXPECT_NE(no_road.exit_code, 0);
  EXPECT_NE(no_road.output.find("must take 21 features"), std::string::npos) << no_road.output;
}

// A bundle that records an option measured and removed (here the orientation entropy feature, or
// negative bags) was trained with code this build does not have: `tod detect` refuses it, naming
// the option and the command that retrains it. The bundle as written loads.
TEST_F(MasksCliTest, BundleWithARemovedOptionIsRefusedByName) {
  const std::string model = (out_ / "model").string();
  const CommandResult run = RunCommand(Train(model));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(Manifest(model)["params"]["orientation_entropy_feature"], false);
  const std::string image = Root() + "/images/2.png";
  const CommandResult fine = DetectForged(
      model, "as_written", [](nlohmann::json&) {}, image);
  EXPECT_EQ(fine.exit_code, 0) << fine.output;
  const CommandResult entropy = DetectForged(
      model, "forged_entropy",
      [](nlohmann::json& m) { m["params"]["orientation_entropy_feature"] = true; }, image);
  EXPECT_NE(entropy.exit_code, 0);
  EXPECT_NE(entropy.output.find("--orientation-entropy-feature"), std::string::npos)
      << entropy.output;
  EXPECT_NE(entropy.output.find("retrain with tod train --data " + Root()), std::string::npos)
      << entropy.output;
  const CommandResult bags = DetectForged(
      model, "forged_bags",
      [](nlohmann::json& m) { m["training"]["parts"]["ordr"]["negative_bags"] = 2; }, image);
  EXPECT_NE(bags.exit_code, 0);
  EXPECT_NE(bags.output.find("--negative-bags"), std::string::npos) << bags.output;
}

}  // namespace

namespace {

// Two trainings' records, `with` a recipe that adds regressor rows: each regressor records `key`
// as `with_value` / `without_value` and has more samples with it, from as many proposals a frame.
void ExpectMoreRegressorSamples(const nlohmann::json& with, const nlohmann::json& without,
                                const char* key, const nlohmann::json& with_value,
                                const nlohmann::json& without_value) {
  for (const char* regressor : {"ordr", "obdr"}) {
    EXPECT_EQ(with["parts"][regressor][key], with_value) << regressor;
    EXPECT_EQ(without["parts"][regressor][key], without_value) << regressor;
    EXPECT_GT(with["parts"][regressor]["samples"].get<int>(),
              without["parts"][regressor]["samples"].get<int>())
        << regressor;
  }
  EXPECT_EQ(with["mean_proposals_per_frame"], without["mean_proposals_per_frame"]);
}

// `tod cv`: two folds of consecutive frames, each trained on the other and evaluated on itself;
// per fold and the mean with its spread, under "cv"; the kept bundles evaluated again without
// training give the same numbers, a bundle of another seed is refused; a LAF-layout set is
// refused (its folds cannot be written as split files).
TEST_F(MasksCliTest, CrossValidationOverFoldsOfConsecutiveFrames) {
  const std::string json = (out_ / "cv.json").string();
  const std::string common = tod_ + " cv --data " + Root() + " --work " + (out_ / "cv").string() +
                             " --folds 2 --seeds 1 --trees 4 --classifier-frames 4 --threads 2";
  const CommandResult cv = RunCommand(common + " --keep-models --json " + json);
  ASSERT_EQ(cv.exit_code, 0) << cv.output;
  EXPECT_NE(cv.output.find("2-fold cross-validation, 1 seed from 1"), std::string::npos)
      << cv.output;
  EXPECT_NE(cv.output.find("BP+Fusion pixel AP"), std::string::npos) << cv.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in)["cv"];
  EXPECT_EQ(j["folds"], 2);
  ASSERT_EQ(j["per_fold"].size(), 2u);
  ASSERT_EQ(j["runs"].size(), 2u);
  // The folds are runs of the listed frames that together hold every one of them once.
  const nlohmann::json& frames = j["fold_frames"];
  int listed = 0;
  std::ifstream split(fs::path(Root()) / "split.txt");
  for (std::string line; std::getline(split, line);) listed += !line.empty() && line[0] != '#';
  EXPECT_EQ(frames[0][2].get<int>() + frames[1][2].get<int>(), listed);
  const std::string ap = "regression/BP+Fusion@4/ap";
  for (int k = 0; k < 2; ++k)
    EXPECT_EQ(j["runs"][k][0]["frames"].get<int>(), frames[k][2].get<int>()) << k;
  ASSERT_TRUE(j["mean"].contains(ap)) << j["mean"].dump();
  EXPECT_LE(j["min"][ap].get<double>(), j["mean"][ap].get<double>());
  EXPECT_GE(j["max"][ap].get<double>(), j["mean"][ap].get<double>());
  EXPECT_TRUE(fs::exists(out_ / "cv" / "fold1-split.txt"));
  EXPECT_TRUE(fs::exists(out_ / "cv" / "fold1-seed1" / "manifest.json"));

  const std::string reused_json = (out_ / "cv-reused.json").string();
  const CommandResult reused = RunCommand(common + " --reuse-models --json " + reused_json);
  ASSERT_EQ(reused.exit_code, 0) << reused.output;
  EXPECT_EQ(reused.output.find("train: "), std::string::npos) << reused.output;
  std::ifstream reused_in(reused_json);
  const nlohmann::json r = nlohmann::json::parse(reused_in)["cv"];
  // Every metric but the stage times.
  for (const auto& [path, value] : j["mean"].items())
    if (path.rfind("timing_ms/", 0) != 0) {
      EXPECT_EQ(r["mean"][path], value) << path;
    }
  // The kept bundles tested on the same frames made into another camera, as that camera.
  const std::string reframed = (out_ / "reframed").string();
  const CommandResult made = RunCommand(tod_ + " reframe --data " + Root() + " --out " + reframed +
                                        " --shift-up 0.1 --format jpg");
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const std::string camera_json = (out_ / "cv-camera.json").string();
  const CommandResult camera = RunCommand(common + " --reuse-models --test-data " + reframed +
                                          " --geometry camera --json " + camera_json);
  ASSERT_EQ(camera.exit_code, 0) << camera.output;
  std::ifstream camera_in(camera_json);
  const nlohmann::json c = nlohmann::json::parse(camera_in)["cv"];
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(c["runs"][k][0]["frames"].get<int>(), frames[k][2].get<int>()) << k;
    EXPECT_EQ(c["runs"][k][0]["geometry"]["mode"], "camera") << k;
  }
  EXPECT_GT(c["mean"]["geometry/median_abs_shift_rows"].get<double>(), 0.0) << c["mean"].dump();

  const CommandResult other_seed = RunCommand(common + " --seed 2 --reuse-models");
  EXPECT_NE(other_seed.exit_code, 0) << other_seed.output;
  EXPECT_NE(other_seed.output.find("--keep-models"), std::string::npos) << other_seed.output;

  const CommandResult laf =
      RunCommand(tod_ + " cv --data " + tod::testing_env::TestData() + " --work " +
                 (out_ / "cv_laf").string() + " --folds 2 --trees 4");
  EXPECT_NE(laf.exit_code, 0) << laf.output;
  EXPECT_NE(laf.output.find("masks layout"), std::string::npos) << laf.output;
}

// `tod reframe` makes the frames another camera's (here one that sees the road a tenth of the
// height higher, JPEG); `tod eval --geometry camera` stands them on the camera's horizon over the
// split, which is the bundle's moved by about the shift; --geometry bundle does not move it.
TEST_F(MasksCliTest, ReframedFramesAreAnotherCameraTheEvalCalibratesTo) {
  const fs::path reframed = out_ / "camera";
  const CommandResult made = RunCommand(tod_ + " reframe --data " + Root() + " --out " +
                                        reframed.string() + " --shift-up 0.1 --format jpg");
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const cv::Mat original = cv::imread((fs::path(Root()) / "images" / "2.png").string());
  const cv::Mat image = cv::imread((reframed / "images" / "2.jpg").string());
  const cv::Mat mask =
      cv::imread((reframed / "labels_masks" / "2.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(image.empty());
  ASSERT_EQ(image.size(), original.size());
  const int shift = original.rows / 10;
  EXPECT_EQ(cv::countNonZero(mask.rowRange(mask.rows - shift, mask.rows) != 255), 0)
      << "the uncovered rows are void";

  const auto eval = [&](const std::string& geometry) {
    const std::string json = (out_ / (geometry + ".json")).string();
    const CommandResult run =
        RunCommand(tod_ + " eval --data " + reframed.string() + " --format masks --model " +
                   tod::testing_env::TestModel() + " --max-frames 6 --threads 2 --geometry " +
                   geometry + " --json " + json);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("Geometry (" + geometry + ")"), std::string::npos) << run.output;
    std::ifstream in(json);
    return nlohmann::json::parse(in);
  };
  const nlohmann::json camera = eval("camera");
  const int frames = camera["frames"].get<int>();
  EXPECT_EQ(camera["geometry"]["mode"], "camera");
  EXPECT_EQ(camera["geometry"]["sources"].value("camera", 0), frames) << camera["geometry"].dump();
  EXPECT_NEAR(camera["geometry"]["median_abs_shift_rows"].get<double>(), shift,
              0.03 * original.rows)
      << camera["geometry"].dump();
  const nlohmann::json bundle = eval("bundle");
  EXPECT_EQ(bundle["geometry"]["sources"].value("bundle", 0), frames) << bundle["geometry"].dump();
  EXPECT_EQ(bundle["geometry"]["median_abs_shift_rows"].get<double>(), 0.0);

  // A set without split.txt is reframed whole.
  ASSERT_TRUE(fs::remove(reframed / "split.txt"));
  const CommandResult again = RunCommand(tod_ + " reframe --data " + reframed.string() + " --out " +
                                         (out_ / "again").string() + " --scale 0.5");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(cv::imread((out_ / "again" / "images" / "2.png").string()).rows, original.rows / 2);
  EXPECT_FALSE(fs::exists(out_ / "again" / "split.txt"));

  const CommandResult bad = RunCommand(tod_ + " reframe --data " + Root() + " --out " +
                                       (out_ / "bad").string() + " --crop 4000x10");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--crop"), std::string::npos) << bad.output;
}

}  // namespace

// Truth boxes as positives (the default): every training obstacle's own box is one more positive
// of both regressors. Recorded per regressor; without them (--paper truth_box_positives) each
// regressor has fewer samples, its proposals the same; the bundle detects.
TEST_F(MasksCliTest, TruthBoxesAddPositivesUnlessTurnedOff) {
  const std::string with_truth = (out_ / "truth").string();
  const std::string paper = (out_ / "paper").string();
  const CommandResult run_truth = RunCommand(Train(with_truth));
  ASSERT_EQ(run_truth.exit_code, 0) << run_truth.output;
  const CommandResult run_paper = RunCommand(Train(paper, "--paper truth_box_positives"));
  ASSERT_EQ(run_paper.exit_code, 0) << run_paper.output;
  const nlohmann::json with = Manifest(with_truth)["training"];
  const nlohmann::json without = Manifest(paper)["training"];
  ExpectMoreRegressorSamples(with, without, "truth_box_positives", true, false);
  const std::string image = (fs::path(Root()) / "images" / "1.webp").string();
  const CommandResult detect = RunCommand(tod_ + " detect --model " + with_truth + " --out " +
                                          (out_ / "det").string() + " " + image);
  EXPECT_EQ(detect.exit_code, 0) << detect.output;
}
