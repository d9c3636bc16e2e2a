#include "core/training/training_calibration.h"

#include <limits>
#include <string>
#include <vector>

#include "core/pipeline/obstacle_calibration.h"
#include "core/pipeline/obstacle_detector.h"
#include "core/training/map_isolation_fit.h"

namespace tod::training {

Status CalibrateObstacleScores(TrainingRun& run, const Survey& survey,
                               const RegressorSamples& samples, const ClassifierFolds& folds,
                               ModelBundle& bundle, nlohmann::json& parts) {
  const auto fold_of = [&folds](int frame) { return folds.FoldOf(frame); };
  MapIsolationFit isolation(
      run.options().fit_map_isolation ? DefaultIsolationExponents() : std::vector<float>{0.f},
      bundle.params, run.num_frames());
  for (int fold = 0; fold < kFolds; ++fold) {
    std::vector<int> which;
    for (int i : survey.usable)
      if (fold_of(i) == fold) which.push_back(i);
    if (which.empty()) continue;
    auto pair = TrainRegressorPair(
        samples, [&](int i) { return fold_of(i) != fold; }, RegressorForest(run.options()));
    if (!pair.ok()) return pair.status().WithContext("calibration fold " + std::to_string(fold));
    // Frames of this fold are scored by parts trained on the other fold only: the regressors and,
    // with out-of-fold maps, the classifiers too.
    ModelBundle fold_bundle = folds.For(bundle, which.front());
    fold_bundle.ordr = std::move(pair->ordr);
    fold_bundle.obdr = std::move(pair->obdr);
    const ObstacleDetector detector(std::move(fold_bundle), "calibration");
    DetectOptions options;
    options.max_proposals = std::numeric_limits<int>::max();  // the map's input: every box
    options.want_probability_map = false;
    const Status st = run.FirstError(which, run.ForEachFrame(which, [&](int i, const Sample& s) {
      FrameTrace trace;
      auto detection = detector.Detect(s.image, options, &trace);
      if (!detection.ok()) return detection.status();
      std::vector<ScoredBox> fused;
      fused.reserve(detection->proposals.size());
      for (const Proposal& p : detection->proposals) fused.push_back({p.box, p.fused});
      return isolation.AddFrame(i, s, trace.map_superpixels(), fused);
    }));
    if (!st.ok()) return st.WithContext("calibrating obstacle scores");
  }
  const int chosen = isolation.Best();
  bundle.params.probability_map.isolation.exponent = isolation.exponent(chosen);
  parts["map_isolation"] = {{"learned", true},
                            {"trained", true},
                            {"fit", run.options().fit_map_isolation},
                            {"folds", kFolds},
                            {"fold_layout", kFoldLayoutName}};
  parts["map_isolation"].update(isolation.ToJson());
  run.Say("map isolation exponent " + std::to_string(isolation.exponent(chosen)));

  std::vector<double> evidence;
  std::vector<int> labels;
  for (const auto& [e, label] : isolation.Components(chosen))
    evidence.push_back(e), labels.push_back(label);
  auto fitted = FitObstacleCalibration(evidence, labels);
  if (!fitted.ok()) {
    // Not an untrained learned part but data without the contrast to fit (e.g. a handful of
    // frames on which every component is an obstacle): said here and recorded, and the bundle's
    // scores stay the raw evidence, as documented for uncalibrated bundles.
    run.Say("obstacle scores NOT calibrated: " + fitted.status().message() +
            "; obstacles report their raw evidence as score");
    bundle.params.obstacle_calibration = ObstacleCalibration{};
    parts["calibration"] = {{"learned", true},
                            {"trained", false},
                            {"reason", fitted.status().message()},
                            {"fold_layout", kFoldLayoutName},
                            {"components", evidence.size()}};
    return Status::Ok();
  }
  bundle.params.obstacle_calibration = *fitted;
  parts["calibration"] = {{"learned", true},
                          {"trained", true},
                          {"folds", kFolds},
                          {"fold_layout", kFoldLayoutName},
                          {"components", fitted->samples},
                          {"on_obstacles", fitted->positives},
                          {"flat", fitted->flat}};
  if (fitted->flat) {
    run.Say(
        "WARNING: obstacle scores are flat: on the training frames, scored out of fold, the "
        "fused scores did not rank the " +
        std::to_string(fitted->positives) + " components on obstacles above the other " +
        std::to_string(fitted->samples - fitted->positives) + "; every obstacle scores " +
        std::to_string(CalibratedScore(*fitted, 0.0)) + " (train on more frames)");
  }
  return Status::Ok();
}

}  // namespace tod::training
