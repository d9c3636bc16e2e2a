// The trainer's geometry step (trainer.h): the multilayer regions, the size filter and the
// ground-plane features' horizons, from the training obstacles. Internal to the trainer.
#pragma once

#include <nlohmann/json.hpp>

#include "core/base/status.h"
#include "core/pipeline/model_bundle.h"
#include "core/training/training_run.h"

namespace tod::training {

// Multilayer regions and the size filter from the training obstacles (§1.4, §4.3).
Status DeriveGeometry(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                      nlohmann::json& parts);

}  // namespace tod::training
