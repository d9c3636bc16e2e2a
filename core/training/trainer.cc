#include "core/training/trainer.h"

#include <string>

#include "core/base/memory_usage.h"
#include "core/edges/edge_labels.h"
#include "core/features/sample_selection.h"
#include "core/proposals/edge_box_scorer.h"
#include "core/training/training_calibration.h"
#include "core/training/training_classifiers.h"
#include "core/training/training_geometry.h"
#include "core/training/training_regressors.h"
#include "core/training/training_run.h"

namespace tod {
namespace {

using training::CalibrateObstacleScores;
using training::ClassifierFolds;
using training::ClassifierFrames;
using training::DeriveGeometry;
using training::RegressorForest;
using training::Regressors;
using training::RegressorSamples;
using training::SecondsSince;
using training::Survey;
using training::SurveyFrames;
using training::TrainEdgeSource;
using training::TrainingRun;
using training::TrainOcclusionClassifier;
using training::TrainRegressors;

// The manifest's record of one regressor ("ordr" or "obdr"): what it learned from and how.
nlohmann::json RegressorPartRecord(const std::string& name, const TrainOptions& options,
                                   const Regressors& regressors, int num_features,
                                   const ClassifierFolds& folds) {
  const bool ordr = name == "ordr";
  const ForestParams forest = RegressorForest(options);
  const SampleSelectionParams selection;
  return {{"learned", true},
          {"trained", true},
          {"samples", ordr ? regressors.ordr_samples : regressors.obdr_samples},
          {"trees", forest.num_trees},
          {"mtry", forest.max_features},
          {"min_leaf", forest.min_leaf_size},
          {"hard_negatives", options.mine_hard_negatives ? "mined" : "objectness"},
          {"negatives_per_range", ordr ? selection.ordr_negatives : selection.obdr_negatives},
          // Bags and pasted copies were measured and removed (docs/findings.md#negative-bags,
          // #pasted-obstacles): recorded at their one value as before, so the manifest reads as
          // older ones and a bundle that records another value is refused (removed_options.h).
          {"negative_bags", 1},
          {"hard_fraction", selection.hard_fraction},
          {"pasted_copies", 0},
          {"truth_box_positives", options.truth_box_positives},
          {"features", num_features},
          {"maps", folds.enabled ? "out_of_fold" : "in_sample"},
          {"fold_layout", kFoldLayoutName}};
}

// The manifest's "training" record: the data, the frames and samples, every part's record and
// the run's seconds and peak memory.
nlohmann::json TrainingRecord(const TrainingRun& run, const Survey& survey,
                              const RegressorSamples& samples, const Regressors& regressors,
                              const nlohmann::json& parts, const nlohmann::json& seconds) {
  const TrainOptions& options = run.options();
  const int n = static_cast<int>(survey.usable.size());
  const ForestParams forest = RegressorForest(options);
  nlohmann::json data = nlohmann::json::array({options.data.data_root});
  for (const std::string& root : options.more_data) data.push_back(root);
  return {{"data", options.more_data.empty() ? nlohmann::json(options.data.data_root) : data},
          {"format", run.format()},
          {"data_terms", options.data_terms},
          {"split", options.data.split},
          {"frames", n},
          {"skipped_frames", SkippedFramesToJson(survey.skipped)},
          {"frame_size", {survey.width, survey.height}},
          {"obstacles", survey.footprints.size()},
          {"regions_from", EnumString(options.regions)},
          {"seed", options.seed},
          {"classifier_frames", ClassifierFrames(run, survey).size()},
          {"mean_proposals_per_frame", static_cast<double>(samples.proposals) / n},
          {"ordr_samples", regressors.ordr_samples},
          {"obdr_samples", regressors.obdr_samples},
          {"parts", parts},
          {"regressor",
           {{"trees", forest.num_trees},
            {"mtry", forest.max_features},
            {"min_leaf", forest.min_leaf_size}}},
          {"peak_rss_mb", PeakRssMb()},
          {"seconds", seconds}};
}

}  // namespace

cv::Mat1i LabelMap(const Sample& sample) {
  cv::Mat1i labels(sample.image.size(), 0);
  labels.setTo(1, sample.road);
  // Void (LAF instanceIds < 1000, the mask benchmarks' 255) stays void in every target (§3.4):
  // the ego-vehicle hood and the rectification border are no object boundaries.
  if (!sample.ignore.empty()) labels.setTo(kIgnoreLabel, sample.ignore);
  for (std::size_t i = 0; i < sample.instances.size(); ++i) {
    const ObstacleInstance& inst = sample.instances[i];
    const Box b = ClipToImage(inst.box, labels.cols, labels.rows);
    if (b.empty() || inst.mask.size() != cv::Size(inst.box.w, inst.box.h)) continue;
    const cv::Rect local(b.x - inst.box.x, b.y - inst.box.y, b.w, b.h);
    labels(b.rect()).setTo(static_cast<int>(2 + i), inst.mask(local));
  }
  return labels;
}

Result<ModelBundle> TrainModel(const TrainOptions& options) {
  // A grid the proposal stage would refuse gives no boxes: say so before any frame is read.
  if (Status st = ValidateEdgeBoxParams(options.params.boxes); !st.ok())
    return Status::InvalidArgument("proposal parameters: " + st.message());
  TrainingRun run(options);
  if (Status st = run.Open(); !st.ok()) return st;
  ModelBundle bundle;
  bundle.params = options.params;
  nlohmann::json parts = nlohmann::json::object();

  run.StartStep();
  auto survey = SurveyFrames(run);
  if (!survey.ok()) return survey.status();
  if (Status st = DeriveGeometry(run, *survey, bundle, parts); !st.ok()) return st;
  run.EndStep("survey");

  ClassifierFolds folds(options.out_of_fold_maps, run.num_frames(), survey->usable,
                        run.FrameSources());
  if (folds.enabled) folds.upstream.fill(bundle);  // parameters, geometry; classifiers below

  run.StartStep();
  if (Status st = TrainEdgeSource(run, *survey, bundle, folds, parts); !st.ok()) return st;
  run.EndStep("edges");

  run.StartStep();
  if (Status st = TrainOcclusionClassifier(run, *survey, bundle, folds, parts); !st.ok()) return st;
  run.EndStep("occlusion");

  auto trained = TrainRegressors(run, *survey, bundle, folds);
  if (!trained.ok()) return trained.status();
  bundle.ordr = std::move(trained->regressors.ordr);
  bundle.obdr = std::move(trained->regressors.obdr);
  const RegressorSamples& samples = trained->samples;
  const Regressors& regressors = trained->regressors;  // its sample counts
  for (const char* name : {"ordr", "obdr"})
    parts[name] = RegressorPartRecord(name, options, regressors, bundle.ordr.num_features(), folds);

  run.StartStep();
  run.Say("calibrating obstacle scores and fitting the map's isolation (2-fold)");
  if (Status st = CalibrateObstacleScores(run, *survey, samples, folds, bundle, parts); !st.ok())
    return st;
  run.EndStep("calibration");

  nlohmann::json seconds = run.seconds();
  seconds["total"] = SecondsSince(run.started());
  bundle.training = TrainingRecord(run, *survey, samples, regressors, parts, seconds);
  bundle.version = "tod-" + NowIso8601().substr(0, 10) + "-seed" + std::to_string(options.seed);
  run.Say("trained in " + std::to_string(static_cast<int>(seconds["total"].get<double>())) + " s");
  return bundle;
}

}  // namespace tod
