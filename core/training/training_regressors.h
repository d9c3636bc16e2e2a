// The trainer's regressor step (trainer.h): ORDR and OBDR samples from every frame's proposals
// (§6), the two forests, and the second round on mined hard negatives. Internal to the trainer.
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "core/base/status.h"
#include "core/forest/random_forest.h"
#include "core/pipeline/model_bundle.h"
#include "core/training/training_classifiers.h"
#include "core/training/training_run.h"

namespace tod::training {

// ORDR and OBDR samples of every frame (§6), kept per frame for the calibration folds.
struct RegressorSamples {
  std::vector<cv::Mat1f> ordr_rows, obdr_rows;
  std::vector<std::vector<float>> ordr_targets, obdr_targets;
  long long proposals = 0;
};

// The regressors trained on the samples of the frames `in_fold(i)` accepts.
struct Regressors {
  RandomForest ordr, obdr;
  int ordr_samples = 0, obdr_samples = 0;
};

// ORDR and OBDR on the samples of the frames `in_fold(i)` accepts.
Result<Regressors> TrainRegressorPair(const RegressorSamples& samples,
                                      const std::function<bool(int)>& in_fold, ForestParams forest);

// The regressors' forest parameters: TrainOptions::regressor with the run's seed and threads.
ForestParams RegressorForest(const TrainOptions& options);

// The regressors and the samples they were trained on (kept for the calibration folds).
struct TrainedRegressors {
  RegressorSamples samples;
  Regressors regressors;
};

// Samples, then ORDR and OBDR (§6); with TrainOptions::mine_hard_negatives a second round
// (bootstrapping): the first round's regressors score every training proposal, the negatives
// are drawn again with their hard share by that score, and the regressors train again.
Result<TrainedRegressors> TrainRegressors(TrainingRun& run, const Survey& survey,
                                          const ModelBundle& bundle, const ClassifierFolds& folds);

}  // namespace tod::training
