// `tod train`: learns every part of the model from a dataset's training split - multilayer
// regions, size filter, pixel edge classifier, occlusion classifier, ORDR and OBDR, the obstacle
// score calibration - and returns the bundle (the caller saves it). Frames are streamed through
// the steps (memory does not grow with the split); a part that cannot be trained fails the run
// with a message naming the step; the manifest records what each part was trained on.
#pragma once

#include "core/data/dataset.h"
#include "core/pipeline/model_bundle.h"
#include "core/training/train_options.h"

namespace tod {

Result<ModelBundle> TrainModel(const TrainOptions& options);

// Per-pixel labels for classifier training: 1 road (free space), 2 + i obstacle instance i,
// kIgnoreLabel (-1) void, 0 everything else.
cv::Mat1i LabelMap(const Sample& sample);

}  // namespace tod
