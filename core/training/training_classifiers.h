// The trainer's classifier steps (trainer.h): the base edge source and the occlusion
// classifier, each with its out-of-fold copies. Internal to the trainer.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/model_bundle.h"
#include "core/training/training_folds.h"
#include "core/training/training_run.h"

namespace tod::training {

// Positions of the frames the edge and occlusion classifiers learn from.
std::vector<int> ClassifierFrames(const TrainingRun& run, const Survey& survey);

// Out-of-fold maps (TrainOptions::out_of_fold_maps). The edge and occlusion classifiers fit the
// frames they were trained on far better than a frame they have never seen, so maps computed on
// training frames with them are cleaner than any test frame's, and whatever learns from those
// maps (the occlusion classifier from edge maps, the regressors from occlusion maps and edge
// features) learns from the wrong distribution. Stacked training: each learned part also gets a
// copy trained on each of two folds of frames, and a frame's maps for the next part come from the
// copy trained on the other fold, as they would on a frame never seen. The folds are runs of
// whole drives (training_folds.h).
constexpr int kFolds = 2;

struct ClassifierFolds {
  bool enabled = false;
  std::vector<int> fold_of;  // fold of every frame position (AssignFolds)
  // upstream[f]: the bundle's parameters with the classifiers trained on fold f's frames.
  std::array<ModelBundle, kFolds> upstream;

  ClassifierFolds(bool on, int num_frames, const std::vector<int>& usable,
                  const std::vector<int>& source)
      : enabled(on), fold_of(AssignFolds(num_frames, usable, kFolds, source)) {}
  int FoldOf(int frame) const { return fold_of[frame]; }
  // The bundle whose classifiers compute frame `i`'s maps for a downstream part.
  const ModelBundle& For(const ModelBundle& bundle, int frame) const {
    return enabled ? upstream[(FoldOf(frame) + 1) % kFolds] : bundle;
  }
  // The positions in `which` that lie in `fold`.
  std::vector<int> InFold(const std::vector<int>& which, int fold) const {
    std::vector<int> out;
    for (int i : which)
      if (FoldOf(i) == fold) out.push_back(i);
    return out;
  }
};

// §3.4 step 1: the base edge source. Samples are extracted frame by frame.
Status TrainEdgeSource(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                       ClassifierFolds& folds, nlohmann::json& parts);

// §3.4 steps 2-5: the occlusion classifier on superpixel boundaries, pairs frame by frame.
Status TrainOcclusionClassifier(TrainingRun& run, const Survey& survey, ModelBundle& bundle,
                                ClassifierFolds& folds, nlohmann::json& parts);

}  // namespace tod::training
