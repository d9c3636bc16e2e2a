// The trainer's calibration step (trainer.h): the map's isolation exponent and the obstacles'
// score calibration, from one out-of-fold pass. Internal to the trainer.
#pragma once

#include <nlohmann/json.hpp>

#include "core/base/status.h"
#include "core/pipeline/model_bundle.h"
#include "core/training/training_classifiers.h"
#include "core/training/training_regressors.h"
#include "core/training/training_run.h"

namespace tod::training {

// Calibration of the obstacles' scores (obstacle_calibration.h) and the map's isolation exponent
// (map_isolation_fit.h), from one out-of-fold pass. The regressors fit their own training frames
// closely, so scores on those frames would be overconfident: each frame is scored by regressors
// trained on the other fold of frames (2-fold cross-fitting). The exponent whose map ranks those
// frames' obstacle pixels best is chosen, then Platt scaling of "covers an obstacle pixel" is
// fitted on the evidence of every component that map yields.
Status CalibrateObstacleScores(TrainingRun& run, const Survey& survey,
                               const RegressorSamples& samples, const ClassifierFolds& folds,
                               ModelBundle& bundle, nlohmann::json& parts);

}  // namespace tod::training
