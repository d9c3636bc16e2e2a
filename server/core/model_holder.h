// The model currently serving, swapped atomically on reload. Each request takes a snapshot
// (shared_ptr) when it starts, so a reload never changes the model under a running request.
#pragma once

#include <memory>
#include <mutex>
#include <string>

#include "core/base/status.h"
#include "core/pipeline/detector.h"

namespace tod::server {

struct LoadedModel {
  std::shared_ptr<const Detector> detector;
  std::string model_dir;
  int generation = 0;     // 1 for the first load, +1 per successful reload
  std::string loaded_at;  // ISO 8601 UTC
  double warm_up_ms = 0;  // the warm-up detection run before it was published (warm_up.h)
};

class ModelHolder {
 public:
  // Loads `model_dir` with Detector::Load and warms it up (one detection on a made-up frame, so
  // no request pays the process's one-off costs) before it becomes current; on failure the
  // current model (if any) stays.
  Status Load(const std::string& model_dir);
  // Serves an already constructed detector (embedding, tests); `model_dir` is what Reload() reads.
  void Install(std::shared_ptr<const Detector> detector, const std::string& model_dir);
  // Loads the directory of the current model again.
  Status Reload();
  // The current model, or nullptr before the first successful load.
  std::shared_ptr<const LoadedModel> Current() const;

 private:
  // Makes `detector` current with the next generation number; load_mutex_ must be held.
  void Publish(std::shared_ptr<const Detector> detector, const std::string& model_dir,
               double warm_up_ms);

  mutable std::mutex mutex_;  // guards current_; loading happens outside it
  std::mutex load_mutex_;     // one load at a time, so generations are sequential
  std::shared_ptr<const LoadedModel> current_;
};

// Current UTC time as "YYYY-MM-DDTHH:MM:SSZ".
std::string UtcNowIso8601();

}  // namespace tod::server
