#include "core/training/training_run.h"

#include <cstdio>

#include "core/base/heap_tuning.h"
#include "core/base/memory_usage.h"
#include "core/pipeline/parallel.h"

namespace tod::training {

Status TrainingRun::Open() {
  std::vector<DatasetSpec> specs = {options_.data.Spec()};
  for (const std::string& root : options_.more_data)
    specs.push_back({root, options_.data.split, "auto", "", options_.data.max_frames});
  auto selection = SelectFrames(specs);
  if (!selection.ok()) return selection.status();
  selection_ = std::move(*selection);
  frames_ = selection_.frames;
  return Status::Ok();
}

void TrainingRun::Say(const std::string& line) {
  if (!options_.progress) return;
  std::lock_guard lock(say_mutex_);
  char rss[48];
  std::snprintf(rss, sizeof rss, " [peak RSS %.0f MB]", PeakRssMb());
  options_.progress(line + rss);
}

std::vector<Status> TrainingRun::ForEachFrame(
    const std::vector<int>& which, const std::function<Status(int, const Sample&)>& body) {
  return ParallelFor(static_cast<int>(which.size()), options_.threads, [&](int j) -> Status {
    Status st = [&] {
      auto sample = selection_.dataset->Load(frames_[which[j]]);
      if (!sample.ok()) return sample.status();
      return body(which[j], *sample);
    }();
    ReleaseFreeHeapPages();  // the frame's tables are freed; what the body kept stays
    return st;
  });
}

Status TrainingRun::FirstError(const std::vector<int>& which,
                               const std::vector<Status>& statuses) const {
  for (std::size_t j = 0; j < statuses.size(); ++j)
    if (!statuses[j].ok()) return statuses[j].WithContext("frame " + FrameName(which[j]));
  return Status::Ok();
}

Result<Survey> SurveyFrames(TrainingRun& run) {
  const int n = run.num_frames();
  run.Say("surveying " + std::to_string(n) + " training frames from " +
          run.options().data.data_root);
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  std::vector<cv::Size> sizes(n);
  std::vector<std::vector<ObstacleFootprint>> per_frame(n);
  std::vector<HorizonEstimate> horizons(n);
  const std::vector<Status> statuses = run.ForEachFrame(all, [&](int i, const Sample& s) {
    sizes[i] = s.image.size();
    horizons[i] = EstimateHorizon(s.image);
    for (const ObstacleInstance& inst : s.instances)
      per_frame[i].push_back({inst.box, inst.pixel_count()});
    return Status::Ok();
  });
  Survey survey;
  const Status bad = ApplyBadFramePolicy(
      statuses, [&](int i) { return run.FrameName(i); }, run.options().data.on_bad_frame,
      &survey.skipped);
  if (!bad.ok()) return bad;
  for (const SkippedFrame& f : survey.skipped)
    run.Say("skipped frame " + f.frame + ": " + f.reason);
  for (int i = 0; i < n; ++i) {
    if (!statuses[i].ok()) continue;
    if (survey.usable.empty()) survey.width = sizes[i].width, survey.height = sizes[i].height;
    if (sizes[i] != cv::Size(survey.width, survey.height)) {
      return Status::InvalidArgument(
          "frame " + run.FrameName(i) + " is " + std::to_string(sizes[i].width) + "x" +
          std::to_string(sizes[i].height) + ", the split's first frame " +
          std::to_string(survey.width) + "x" + std::to_string(survey.height) +
          ": train on frames of one camera (a bundle then maps onto any frame size)");
    }
    survey.usable.push_back(i);
    survey.horizons.push_back(horizons[i]);
    for (const ObstacleFootprint& f : per_frame[i]) {
      survey.footprints.push_back(f);
      survey.obstacle_boxes.push_back(f.box);
    }
  }
  if (survey.usable.empty()) return Status::InvalidArgument("no usable training frame");
  run.Say(std::to_string(survey.footprints.size()) + " training obstacles in " +
          std::to_string(survey.usable.size()) + " frames");
  return survey;
}

}  // namespace tod::training
