#include "core/validation/cross_validation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/datasets/dataset_factory.h"
#include "core/pipeline/model_bundle.h"

namespace tod {
namespace {

namespace fs = std::filesystem;

bool AllDigits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Frame order: numeric names by number (so 9 before 10), then the others by name.
bool FrameOrder(const std::string& a, const std::string& b) {
  const bool na = AllDigits(a), nb = AllDigits(b);
  if (na != nb) return na;
  if (na && a.size() != b.size()) return a.size() < b.size();
  return a < b;
}

// The split file of fold k: its frames under "test", every other frame under "train".
std::string FoldSplitFile(const std::vector<CvFold>& folds, std::size_t k) {
  std::string text = "# cross-validation fold " + std::to_string(k + 1) + " of " +
                     std::to_string(folds.size()) + "\n";
  for (std::size_t f = 0; f < folds.size(); ++f)
    for (const std::string& stem : folds[f].stems)
      text += (f == k ? "test " : "train ") + stem + "\n";
  return text;
}

// The stems of every frame of the recipe's dataset (its split file's listed ones, if any).
Result<std::vector<std::string>> AllStems(const TrainOptions& recipe) {
  std::string format = recipe.data.format;
  if (format == "auto") {
    auto detected = DetectDatasetFormat(recipe.data.data_root);
    if (!detected.ok()) return detected.status();
    format = *detected;
  }
  if (format != "masks")
    return Status::InvalidArgument(
        "cross-validation needs a dataset in the masks layout (images/ + labels_masks/), whose "
        "folds it writes as split files; " +
        recipe.data.data_root + " is " + format);
  DatasetSpec spec;
  spec.root = recipe.data.data_root;
  spec.format = format;
  spec.split = "all";
  spec.split_file = recipe.data.split_file;
  auto selection = SelectFrames(spec);
  if (!selection.ok()) return selection.status();
  std::vector<std::string> stems;
  for (int i : selection->frames) stems.push_back(selection->dataset->name(i));
  return stems;
}

void Say(const CrossValidationOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

// Beside a kept bundle: the fold's split file it was trained on.
constexpr const char* kKeptSplitName = "cv-split.txt";

std::string ReadWholeFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return in ? std::string(std::istreambuf_iterator<char>(in), {}) : std::string();
}

// The bundle a keep_models run left in `model_dir`, if it was trained on this fold's split (the
// split file kept beside it) with `seed` (its manifest) on the recipe's data.
Result<ModelBundle> LoadKeptFoldBundle(const std::string& model_dir, const TrainOptions& recipe,
                                       const std::string& split, std::uint64_t seed) {
  const std::string kept_split = ReadWholeFile(fs::path(model_dir) / kKeptSplitName);
  if (kept_split.empty())
    return Status::NotFound("no kept bundle in " + model_dir +
                            " (run tod cv with --keep-models first)");
  auto bundle = LoadModelBundle(model_dir);
  if (!bundle.ok()) return bundle.status();
  std::ifstream in(fs::path(model_dir) / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  const nlohmann::json training =
      manifest.is_object() ? manifest.value("training", nlohmann::json()) : nlohmann::json();
  if (kept_split != ReadWholeFile(split) || !training.is_object() ||
      training.value("seed", std::uint64_t{0}) != seed ||
      training.value("data", std::string()) != recipe.data.data_root)
    return Status::FailedPrecondition(model_dir + " was not trained on this fold of " +
                                      recipe.data.data_root + " with seed " + std::to_string(seed));
  return bundle;
}

// This fold's bundle under one seed: trained on the other folds (and kept, with its split file,
// when asked), or the kept one.
Result<ModelBundle> FoldBundle(const TrainOptions& recipe, const CrossValidationOptions& options,
                               const std::string& split, const std::string& model_dir,
                               std::uint64_t seed) {
  if (options.reuse_models) return LoadKeptFoldBundle(model_dir, recipe, split, seed);
  TrainOptions train = recipe;
  train.data.split = "train";
  train.data.split_file = split;
  train.seed = seed;
  auto bundle = TrainModel(train);
  if (!bundle.ok()) return bundle.status();
  if (options.keep_models) {
    if (Status st = SaveModelBundle(*bundle, model_dir, recipe.sed_model); !st.ok()) return st;
    const Status st =
        WriteFileAtomically((fs::path(model_dir) / kKeptSplitName).string(), ReadWholeFile(split));
    if (!st.ok()) return st;
  }
  return bundle;
}

// One fold under one seed: its bundle, evaluated on the fold.
Result<nlohmann::json> RunFold(const TrainOptions& recipe, const EvalOptions& eval,
                               const CrossValidationOptions& options, const std::string& split,
                               const std::string& model_dir, std::uint64_t seed) {
  auto bundle = FoldBundle(recipe, options, split, model_dir, seed);
  if (!bundle.ok()) return bundle.status();
  EvalOptions test = eval;
  test.data = recipe.data;
  if (!options.test_data.empty()) test.data.data_root = options.test_data;
  test.data.split = "test";
  test.data.split_file = split;
  auto report = EvaluateModel(*bundle, test);
  if (!report.ok()) return report.status();
  return EvalReportToJson(*report);
}

void Flatten(const nlohmann::json& node, const std::string& path,
             std::map<std::string, double>& out) {
  if (node.is_object()) {
    for (const auto& [key, value] : node.items())
      Flatten(value, path.empty() ? key : path + "/" + key, out);
  } else if (node.is_number()) {
    out[path] = node.get<double>();
  }
}

struct Spread {
  double mean = 0, min = 0, max = 0;
  int folds = 0;  // where defined
};

// Per fold the mean over its seeds; then over the folds.
std::vector<std::map<std::string, double>> PerFoldMeans(const CrossValidationReport& report) {
  std::vector<std::map<std::string, double>> per_fold;
  for (const std::vector<nlohmann::json>& seeds : report.runs) {
    std::map<std::string, std::pair<double, int>> sums;
    for (const nlohmann::json& run : seeds)
      for (const auto& [path, value] : FlattenMetrics(run)) {
        if (!std::isfinite(value)) continue;
        sums[path].first += value;
        ++sums[path].second;
      }
    std::map<std::string, double> means;
    for (const auto& [path, sum] : sums) means[path] = sum.first / sum.second;
    per_fold.push_back(std::move(means));
  }
  return per_fold;
}

std::map<std::string, Spread> OverFolds(const std::vector<std::map<std::string, double>>& folds) {
  std::map<std::string, Spread> out;
  for (const auto& fold : folds)
    for (const auto& [path, value] : fold) {
      Spread& s = out[path];
      s.min = s.folds == 0 ? value : std::min(s.min, value);
      s.max = s.folds == 0 ? value : std::max(s.max, value);
      s.mean += value;
      ++s.folds;
    }
  for (auto& [path, s] : out) s.mean /= s.folds;
  return out;
}

}  // namespace

Result<std::vector<CvFold>> ConsecutiveFolds(std::vector<std::string> stems, int folds) {
  if (folds < 2) return Status::InvalidArgument("cross-validation needs at least 2 folds");
  if (static_cast<int>(stems.size()) < folds)
    return Status::InvalidArgument("cross-validation over " + std::to_string(folds) +
                                   " folds needs at least as many frames; the set has " +
                                   std::to_string(stems.size()));
  std::sort(stems.begin(), stems.end(), FrameOrder);
  std::vector<CvFold> out(folds);
  const std::size_t n = stems.size();
  for (int k = 0; k < folds; ++k) {
    const std::size_t begin = n * k / folds, end = n * (k + 1) / folds;
    out[k].stems.assign(stems.begin() + begin, stems.begin() + end);
  }
  return out;
}

Result<CrossValidationReport> CrossValidate(const TrainOptions& recipe, const EvalOptions& eval,
                                            const CrossValidationOptions& options) {
  if (options.seeds < 1) return Status::InvalidArgument("cross-validation needs at least 1 seed");
  if (options.work_dir.empty())
    return Status::InvalidArgument("cross-validation needs a work directory");
  auto stems = AllStems(recipe);
  if (!stems.ok()) return stems.status();
  auto folds = ConsecutiveFolds(std::move(*stems), options.folds);
  if (!folds.ok()) return folds.status();
  std::error_code ec;
  fs::create_directories(options.work_dir, ec);
  if (ec)
    return Status::FailedPrecondition("cannot create " + options.work_dir + ": " + ec.message());

  CrossValidationReport report;
  report.seeds = options.seeds;
  report.first_seed = recipe.seed;
  report.folds = std::move(*folds);
  report.runs.resize(report.folds.size());
  for (std::size_t k = 0; k < report.folds.size(); ++k) {
    const std::string fold = "fold" + std::to_string(k + 1);
    const std::string split = (fs::path(options.work_dir) / (fold + "-split.txt")).string();
    if (Status st = WriteFileAtomically(split, FoldSplitFile(report.folds, k)); !st.ok()) return st;
    for (int s = 0; s < options.seeds; ++s) {
      const std::uint64_t seed = recipe.seed + static_cast<std::uint64_t>(s);
      Say(options, fold + " of " + std::to_string(report.folds.size()) + " (frames " +
                       report.folds[k].stems.front() + "-" + report.folds[k].stems.back() +
                       "), seed " + std::to_string(seed));
      const std::string model =
          (fs::path(options.work_dir) / (fold + "-seed" + std::to_string(seed))).string();
      auto run = RunFold(recipe, eval, options, split, model, seed);
      if (!run.ok()) return run.status().WithContext(fold + ", seed " + std::to_string(seed));
      report.runs[k].push_back(std::move(*run));
    }
  }
  return report;
}

std::map<std::string, double> FlattenMetrics(const nlohmann::json& eval) {
  std::map<std::string, double> out;
  Flatten(eval, "", out);
  return out;
}

nlohmann::json CrossValidationToJson(const CrossValidationReport& report) {
  const std::vector<std::map<std::string, double>> per_fold = PerFoldMeans(report);
  nlohmann::json cv;
  cv["folds"] = report.folds.size();
  cv["seeds"] = report.seeds;
  cv["first_seed"] = report.first_seed;
  cv["fold_frames"] = nlohmann::json::array();
  for (const CvFold& f : report.folds)
    cv["fold_frames"].push_back({f.stems.front(), f.stems.back(), f.stems.size()});
  cv["per_fold"] = per_fold;
  nlohmann::json mean = nlohmann::json::object(), min = mean, max = mean;
  for (const auto& [path, s] : OverFolds(per_fold)) {
    mean[path] = s.mean;
    min[path] = s.min;
    max[path] = s.max;
  }
  cv["mean"] = mean;
  cv["min"] = min;
  cv["max"] = max;
  cv["runs"] = report.runs;
  return cv;
}

std::string FormatCrossValidation(const CrossValidationReport& report) {
  static const std::vector<std::pair<std::string, std::string>> kHeadline = {
      {"regression/BP+Fusion@4/tpr_at_fpr/0.020", "BP+Fusion TPR@FPR 0.02"},
      {"regression/BP+Fusion@4/ap", "BP+Fusion pixel AP"},
      {"regression/BP+Fusion@4/fpr_at_tpr95", "BP+Fusion FPR@95"},
      {"calibrated_map/tpr_at_fpr/0.020", "served map TPR@FPR 0.02"},
      {"calibrated_map/ap", "served map pixel AP"},
      {"regression/BP+Fusion@4/ar/1000", "BP+Fusion AR@1000"},
      {"proposals/OAOCC+OLP@4+MS/ar/1000", "proposals AR@1000"},
      {"components/mean_f1", "SMIYC mean F1 (map)"},
      {"calibrated_map/components/mean_f1", "SMIYC mean F1 (cal map)"},
      {"obstacles/found_iou50", "obstacles found IoU 0.5"},
      {"obstacles/found_iou25", "obstacles found IoU 0.25"},
      {"obstacles/instances_found", "obstacles overlapped"},
      {"obstacles/components/mean_f1", "SMIYC mean F1 (list)"},
      {"obstacles/false_alarms_per_frame", "false alarms / frame"},
  };
  const std::vector<std::map<std::string, double>> per_fold = PerFoldMeans(report);
  const std::map<std::string, Spread> spread = OverFolds(per_fold);
  std::ostringstream out;
  char cell[64];
  out << report.folds.size() << "-fold cross-validation, " << report.seeds << " seed"
      << (report.seeds == 1 ? "" : "s") << " from " << report.first_seed << "\n";
  std::snprintf(cell, sizeof cell, "%-26s", "metric");
  out << cell;
  for (const CvFold& f : report.folds) {
    std::snprintf(cell, sizeof cell, " %9s", (f.stems.front() + "-" + f.stems.back()).c_str());
    out << cell;
  }
  out << "      mean   min-max\n";
  for (const auto& [path, label] : kHeadline) {
    const auto s = spread.find(path);
    if (s == spread.end()) continue;
    std::snprintf(cell, sizeof cell, "%-26s", label.c_str());
    out << cell;
    for (const auto& fold : per_fold) {
      const auto v = fold.find(path);
      if (v == fold.end())
        std::snprintf(cell, sizeof cell, " %9s", "-");
      else
        std::snprintf(cell, sizeof cell, " %9.3f", v->second);
      out << cell;
    }
    std::snprintf(cell, sizeof cell, " %9.3f   %.3f-%.3f\n", s->second.mean, s->second.min,
                  s->second.max);
    out << cell;
  }
  return out.str();
}

}  // namespace tod
