#include "core/pipeline/removed_options.h"

namespace tod {
namespace {

constexpr char kParams[] = "/params";

std::vector<RemovedOption> MakeRemovedOptions() {
  std::vector<RemovedOption> all = {
      {"--orientation-entropy-feature", "/params/orientation_entropy_feature", false,
       "orientation-entropy-feature"},
      {"params.edge_screening", "/params/edge_screening/trees", 0, "edge-screening"},
      {"params.edge_screening", "/params/edge_screening/final_at_most", 0.0, "edge-screening"},
      {"--occlusion-size-features ground_plane", "/params/occlusion_features/ground_plane_size",
       false, "occlusion-size-features"},
      {"--occlusion-size-features ground_plane", "/params/occlusion_features/horizon_y", 0.0,
       "occlusion-size-features"},
      {"--superpixel-strips", "/params/superpixels/strip_rows", 0, "superpixel-strips"},
      {"--occlusion-size-features ground_plane", "/training/parts/occlusion_features/size", "paper",
       "occlusion-size-features"},
      {"--edge-negatives", "/training/parts/edges/negatives_per_positive", 1.0,
       "edge-and-occlusion-negatives"},
      {"--occlusion-negatives", "/training/parts/occlusion/negatives_per_positive", 4,
       "edge-and-occlusion-negatives"},
      {"--regressor-mtry", "/training/regressor/mtry", 6,
       "regressor-mtry-min-leaf-and-hard-fraction"},
      {"--regressor-min-leaf", "/training/regressor/min_leaf", 5,
       "regressor-mtry-min-leaf-and-hard-fraction"},
  };
  for (const std::string part : {"calibration", "map_isolation", "occlusion", "ordr", "obdr"})
    all.push_back({"--fold-layout alternate", "/training/parts/" + part + "/fold_layout", "blocks",
                   "alternate-fold-layout"});
  for (const std::string part : {"ordr", "obdr"}) {
    const std::string at = "/training/parts/" + part + "/";
    all.push_back({"--negative-bags", at + "negative_bags", 1, "negative-bags"});
    all.push_back({"--paste-obstacles", at + "pasted_copies", 0, "pasted-obstacles"});
    all.push_back(
        {"--regressor-mtry", at + "mtry", 6, "regressor-mtry-min-leaf-and-hard-fraction"});
    all.push_back(
        {"--regressor-min-leaf", at + "min_leaf", 5, "regressor-mtry-min-leaf-and-hard-fraction"});
    all.push_back({"--hard-fraction", at + "hard_fraction", 0.2,
                   "regressor-mtry-min-leaf-and-hard-fraction"});
    // The paper's counts per vertical range (SampleSelectionParams), before any scaling.
    const int count = part == "ordr" ? 17 : 25;
    all.push_back({"--negatives-scale", at + "negatives_per_range",
                   nlohmann::json::array({count, count, count, count}), "negatives-scale"});
  }
  return all;
}

// `tod train` with what the manifest's own record says it was trained on.
std::string RetrainCommand(const nlohmann::json& manifest) {
  const nlohmann::json training = manifest.value("training", nlohmann::json::object());
  std::string command = "tod train";
  const nlohmann::json data =
      training.is_object() ? training.value("data", nlohmann::json()) : nlohmann::json();
  const auto add_data = [&](const nlohmann::json& root, const char* flag) {
    command += std::string(" ") + flag + " " + (root.is_string() ? root.get<std::string>() : "DIR");
  };
  if (data.is_array() && !data.empty()) {
    add_data(data.front(), "--data");
    for (std::size_t i = 1; i < data.size(); ++i) add_data(data[i], "--add-data");
  } else {
    add_data(data, "--data");
  }
  if (training.is_object() && training.contains("seed") && training["seed"].is_number_integer())
    command += " --seed " + training["seed"].dump();
  return command + " --out DIR";
}

}  // namespace

const std::vector<RemovedOption>& RemovedOptions() {
  static const std::vector<RemovedOption> all = MakeRemovedOptions();
  return all;
}

void WriteRemovedParams(nlohmann::json& params) {
  for (const RemovedOption& option : RemovedOptions()) {
    if (option.key.rfind(kParams, 0) != 0) continue;
    params[nlohmann::json::json_pointer(option.key.substr(sizeof kParams - 1))] = option.value;
  }
}

Status RefuseRemovedOptions(const nlohmann::json& manifest, const std::string& where) {
  for (const RemovedOption& option : RemovedOptions()) {
    const nlohmann::json::json_pointer key(option.key);
    if (!manifest.contains(key) || manifest.at(key) == option.value) continue;
    return Status::FailedPrecondition(
        where + ": the bundle was trained with " + option.flag + " (" + option.key.substr(1) +
        " = " + manifest.at(key).dump() +
        "), an option measured, not adopted and removed from tod "
        "(docs/findings.md#" +
        option.finding + "); retrain with " + RetrainCommand(manifest) +
        " (every option it used that remains keeps its flag)");
  }
  return Status::Ok();
}

}  // namespace tod
