// One `tod train` run's frames and bookkeeping, and its first pass over the split (trainer.h).
// Internal to the trainer: the steps of TrainModel share these.
#pragma once

#include <chrono>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/status.h"
#include "core/base/types.h"
#include "core/calibration/horizon_estimator.h"
#include "core/datasets/bad_frames.h"
#include "core/datasets/dataset_factory.h"
#include "core/training/train_options.h"

namespace tod::training {

using Clock = std::chrono::steady_clock;

inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// One training run: the split, progress lines (each with the peak RSS so far), step timings.
// Frames are streamed: every step loads the frames it visits and keeps only what the next step
// needs (samples, statistics), so memory does not grow with the number of frames.
class TrainingRun {
 public:
  explicit TrainingRun(const TrainOptions& options) : options_(options) {}

  // Selects the split's frames (data_root, then more_data).
  Status Open();
  // A progress line, with the peak RSS so far.
  void Say(const std::string& line);
  void StartStep() { step_started_ = Clock::now(); }
  void EndStep(const std::string& name) { seconds_[name] = SecondsSince(step_started_); }

  // Runs body(frame index, sample) over `which` (positions into frames()), loading each frame
  // when it is visited. A frame that fails is that frame's error.
  std::vector<Status> ForEachFrame(const std::vector<int>& which,
                                   const std::function<Status(int, const Sample&)>& body);
  // The error of the first frame that failed, named.
  Status FirstError(const std::vector<int>& which, const std::vector<Status>& statuses) const;
  std::string FrameName(int position) const { return selection_.dataset->name(frames_[position]); }
  // Which of the datasets (data_root, then more_data) each frame position comes from.
  const std::vector<int>& FrameSources() const { return selection_.source; }

  const TrainOptions& options() const { return options_; }
  const std::string& format() const { return selection_.format; }
  int num_frames() const { return static_cast<int>(frames_.size()); }
  const nlohmann::json& seconds() const { return seconds_; }
  Clock::time_point started() const { return started_; }

 private:
  const TrainOptions& options_;
  FrameSelection selection_;
  std::vector<int> frames_;
  std::mutex say_mutex_;
  Clock::time_point started_ = Clock::now();
  Clock::time_point step_started_ = Clock::now();
  nlohmann::json seconds_ = nlohmann::json::object();
};

// What the first pass over the split learns: the frame size, the obstacles, the usable frames.
struct Survey {
  int width = 0, height = 0;
  std::vector<ObstacleFootprint> footprints;
  std::vector<Box> obstacle_boxes;
  std::vector<int> usable;  // positions of the frames every later step visits
  std::vector<SkippedFrame> skipped;
  std::vector<HorizonEstimate> horizons;  // per usable frame: the bundle's horizon reference
};

// The first pass: every frame's size and obstacles; frames that cannot
// be read are skipped or fail the run (TrainOptions::on_bad_frame); all must share one size.
Result<Survey> SurveyFrames(TrainingRun& run);

}  // namespace tod::training
