#include "core/pipeline/model_bundle.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>

#include "core/base/binary_io.h"
#include "core/pipeline/removed_options.h"
#include "tests/forest/fitted_forest.h"
#include "tests/test_env.h"

namespace tod {
namespace {
namespace fs = std::filesystem;

class ModelBundleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("tod_bundle_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static ModelBundle SmallBundle(std::uint64_t seed) {
    ModelBundle b;
    b.edge_kind = EdgeKind::kGradient;
    b.edges = CreateGradientEdgeSource();
    b.regions = Laf2020Regions();
    b.size_filter = SizeFilter::Laf2020();
    std::mt19937 rng(static_cast<unsigned>(seed));
    std::uniform_real_distribution<float> u(0, 1);
    cv::Mat1f x(200, 20);
    std::vector<float> y(200);
    for (int i = 0; i < x.rows; ++i) {
      for (int j = 0; j < 20; ++j) x(i, j) = u(rng);
      y[i] = x(i, 0) > 0.5f ? 1.f : 0.f;
    }
    ForestParams fp;
    fp.num_trees = 5;
    fp.seed = seed;
    b.ordr = FittedForest(x, y, fp);
    b.obdr = FittedForest(x, y, fp);
    b.version = "test";
    // The occlusion classifier is left untrained here, which a bundle may only ship on purpose.
    b.training = {{"data", "unit test"}, {"parts", {{"occlusion", {{"off", true}}}}}};
    return b;
  }
  std::string Path(const std::string& name = "model") const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The shipped bundle was written before core/base/binary_io.h served every model file: it must
// still load, and writing its parts again must give the very same bytes (the formats did not
// change).
TEST(ShippedModelBundle, LoadsAndEveryLearnedFileReencodesByteForByte) {
  const fs::path dir = fs::path(testing_env::SourceDir()) / "models" / "default";
  const Result<ModelBundle> bundle = LoadModelBundle(dir.string());
  ASSERT_TRUE(bundle.ok()) << bundle.status().message();
  ASSERT_EQ(bundle->edge_kind, EdgeKind::kPixelForest);
  const auto* edges = dynamic_cast<const PixelEdgeClassifier*>(bundle->edges.get());
  ASSERT_NE(edges, nullptr);
  EXPECT_EQ(EncodeModel(*edges).value(), FileBytes(dir / "edges.bin"));
  EXPECT_EQ(EncodeModel(bundle->occlusion).value(), FileBytes(dir / "occlusion.bin"));
  EXPECT_EQ(EncodeModel(bundle->ordr).value(), FileBytes(dir / "ordr.bin"));
  EXPECT_EQ(EncodeModel(bundle->obdr).value(), FileBytes(dir / "obdr.bin"));
}

TEST_F(ModelBundleTest, UntrainedOcclusionClassifierIsAnErrorUnlessSwitchedOff) {
  ModelBundle b = SmallBundle(4);
  b.training = {{"data", "unit test"}};
  ASSERT_TRUE(SaveModelBundle(b, Path()).ok());
  auto loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("untrained"), std::string::npos);
}

TEST_F(ModelBundleTest, SaveLoadRoundTripKeepsEveryPart) {
  const ModelBundle b = SmallBundle(3);
  ASSERT_TRUE(SaveModelBundle(b, Path()).ok());
  auto loaded = LoadModelBundle(Path());
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->regions.layers, b.regions.layers);
  EXPECT_EQ(loaded->edge_kind, EdgeKind::kGradient);
  EXPECT_EQ(loaded->version, "test");
  EXPECT_FALSE(loaded->created.empty());
  const float row[20] = {0.9f};
  EXPECT_FLOAT_EQ(loaded->ordr.Predict(row), b.ordr.Predict(row));
  EXPECT_EQ(loaded->size_filter.bands.size(), b.size_filter.bands.size());
  // No temporary directory is left next to the bundle.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir_)) entries += e.is_directory();
  EXPECT_EQ(entries, 1);
}

TEST_F(ModelBundleTest, ReplacingAnExistingBundleIsAtomic) {
  ASSERT_TRUE(SaveModelBundle(SmallBundle(1), Path()).ok());
  ModelBundle second = SmallBundle(2);
  second.version = "second";
  ASSERT_TRUE(SaveModelBundle(second, Path()).ok());
  auto loaded = LoadModelBundle(Path());
  ASSERT_TRUE(loaded.ok());
  EXPECT_EQ(loaded->version, "second");
}

TEST_F(ModelBundleTest, TruncatedFileIsNamed) {
  ASSERT_TRUE(SaveModelBundle(SmallBundle(1), Path()).ok());
  const fs::path ordr = fs::path(Path()) / "ordr.bin";
  fs::resize_file(ordr, fs::file_size(ordr) / 2);
  auto loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("ordr.bin"), std::string::npos);
  EXPECT_NE(loaded.status().message().find("truncated"), std::string::npos);
}

TEST_F(ModelBundleTest, MissingFileIsNamed) {
  ASSERT_TRUE(SaveModelBundle(SmallBundle(1), Path()).ok());
  fs::remove(fs::path(Path()) / "occlusion.bin");
  auto loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("occlusion.bin"), std::string::npos);
  EXPECT_NE(loaded.status().message().find("missing"), std::string::npos);
}

TEST_F(ModelBundleTest, WrongFormatVersionAndBrokenManifestAreRefused) {
  ASSERT_TRUE(SaveModelBundle(SmallBundle(1), Path()).ok());
  const fs::path manifest = fs::path(Path()) / "manifest.json";
  std::ifstream in(manifest);
  nlohmann::json j = nlohmann::json::parse(in);
  in.close();
  j["format_version"] = 99;
  std::ofstream(manifest) << j.dump();
  auto loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("format_version 99"), std::string::npos);
  j["format_version"] = 1e30;  // once converted to int unchecked: undefined behaviour
  std::ofstream(manifest) << j.dump();
  loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(loaded.status().message().find("format_version"), std::string::npos);
  std::ofstream(manifest) << "{ not json";
  loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("manifest.json"), std::string::npos);
}

// The manifest's edge_source decides the base edge source: an unknown kind is named, and a
// "sed" bundle without its model file is refused, never loaded with another source.
TEST_F(ModelBundleTest, UnknownEdgeSourceAndMissingSedModelAreRefused) {
  ASSERT_TRUE(SaveModelBundle(SmallBundle(1), Path()).ok());
  auto loaded = LoadModelBundle(Path());
  ASSERT_TRUE(loaded.ok()) << loaded.status().message();
  EXPECT_EQ(loaded->edges->kind(), EdgeKind::kGradient);
  const fs::path manifest = fs::path(Path()) / "manifest.json";
  std::ifstream in(manifest);
  nlohmann::json j = nlohmann::json::parse(in);
  in.close();
  j["edge_source"] = "canny";
  std::ofstream(manifest) << j.dump();
  loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(loaded.status().message().find("canny"), std::string::npos);
  j["edge_source"] = "sed";
  std::ofstream(manifest) << j.dump();
  loaded = LoadModelBundle(Path());
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("sed_model.yml.gz"), std::string::npos);
}

TEST_F(ModelBundleTest, MissingDirectory) {
  auto loaded = LoadModelBundle(Path("nowhere"));
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), StatusCode::kNotFound);
}

TEST_F(ModelBundleTest, EvalNumbersAreAddedToTheManifest) {
  ASSERT_TRUE(SaveModelBundle(SmallBundle(1), Path()).ok());
  ASSERT_TRUE(UpdateManifestField(Path(), "eval", {{"frames", 3}}).ok());
  auto loaded = LoadModelBundle(Path());
  ASSERT_TRUE(loaded.ok());
  EXPECT_EQ(loaded->eval["frames"], 3);
}

// A bundle whose manifest records an option measured and removed (docs/findings.md, "Real frames,
// not adopted") is refused, naming the option and how to retrain; one written now records every
// removed key at its one value and loads, and so does one that predates the keys.
TEST_F(ModelBundleTest, RemovedOptionsAreRefusedByNameOthersLoad) {
  ModelBundle bundle = SmallBundle(3);
  bundle.training["seed"] = 3;
  ASSERT_TRUE(SaveModelBundle(bundle, Path()).ok());
  const fs::path manifest_path = fs::path(Path()) / "manifest.json";
  const nlohmann::json written = nlohmann::json::parse(FileBytes(manifest_path));
  EXPECT_EQ(written["params"]["orientation_entropy_feature"], false);
  EXPECT_EQ(written["params"]["superpixels"]["strip_rows"], 0);
  EXPECT_EQ(written["params"]["edge_screening"]["trees"], 0);
  EXPECT_EQ(written["params"]["occlusion_features"]["ground_plane_size"], false);
  ASSERT_TRUE(LoadModelBundle(Path()).ok());

  const auto load_with = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = written;
    edit(j);
    std::ofstream(manifest_path) << j.dump(2);
    return LoadModelBundle(Path());
  };
  const auto entropy =
      load_with([](nlohmann::json& j) { j["params"]["orientation_entropy_feature"] = true; });
  ASSERT_FALSE(entropy.ok());
  EXPECT_EQ(entropy.status().code(), StatusCode::kFailedPrecondition);
  const std::string message = entropy.status().message();
  EXPECT_NE(message.find("--orientation-entropy-feature"), std::string::npos) << message;
  EXPECT_NE(message.find("docs/findings.md#orientation-entropy-feature"), std::string::npos);
  EXPECT_NE(message.find("retrain with tod train --data unit test --seed 3 --out DIR"),
            std::string::npos)
      << message;
  const auto strips =
      load_with([](nlohmann::json& j) { j["params"]["superpixels"]["strip_rows"] = 32; });
  ASSERT_FALSE(strips.ok());
  EXPECT_NE(strips.status().message().find("--superpixel-strips"), std::string::npos);
  const auto folds = load_with([](nlohmann::json& j) {
    j["training"]["parts"]["ordr"] = {{"fold_layout", "alternate"}, {"negative_bags", 1}};
  });
  ASSERT_FALSE(folds.ok());
  EXPECT_NE(folds.status().message().find("--fold-layout alternate"), std::string::npos);
  // Written before the keys existed: nothing to refuse.
  EXPECT_TRUE(load_with([](nlohmann::json& j) {
                j["params"].erase("orientation_entropy_feature");
                j["params"].erase("edge_screening");
                j["params"].erase("occlusion_features");
                j["params"]["superpixels"].erase("strip_rows");
              }).ok());
}

// models/default was written before the removal and records every removed key it knows at the
// value that remains: it loads (ShippedModelBundle above), and nothing in it is refused.
TEST(ShippedModelBundle, RecordsEveryRemovedOptionAtItsRemainingValue) {
  const fs::path manifest = fs::path(testing_env::SourceDir()) / "models/default/manifest.json";
  const nlohmann::json j = nlohmann::json::parse(FileBytes(manifest));
  EXPECT_TRUE(RefuseRemovedOptions(j, manifest.string()).ok());
  for (const RemovedOption& option : RemovedOptions()) {
    const nlohmann::json::json_pointer key(option.key);
    ASSERT_TRUE(j.contains(key)) << option.key;
    EXPECT_EQ(j.at(key), option.value) << option.key;
  }
}

}  // namespace
}  // namespace tod
