#include "server/core/model_holder.h"

#include <ctime>

#include "core/pipeline/warm_up.h"

namespace tod::server {

std::string UtcNowIso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

Status ModelHolder::Load(const std::string& model_dir) {
  std::lock_guard load_lock(load_mutex_);
  Result<std::shared_ptr<const Detector>> detector = Detector::Load(model_dir);
  if (!detector.ok()) return detector.status();
  if (*detector == nullptr) return Status::Internal("model loader returned no detector");
  const Result<double> warm_up_ms = WarmUp(**detector);
  if (!warm_up_ms.ok()) return warm_up_ms.status().WithContext(model_dir);
  Publish(std::move(*detector), model_dir, *warm_up_ms);
  return Status::Ok();
}

void ModelHolder::Install(std::shared_ptr<const Detector> detector, const std::string& model_dir) {
  std::lock_guard load_lock(load_mutex_);
  Publish(std::move(detector), model_dir, /*warm_up_ms=*/0);
}

void ModelHolder::Publish(std::shared_ptr<const Detector> detector, const std::string& model_dir,
                          double warm_up_ms) {
  auto model = std::make_shared<LoadedModel>();
  model->warm_up_ms = warm_up_ms;
  model->detector = std::move(detector);
  model->model_dir = model_dir;
  model->loaded_at = UtcNowIso8601();
  std::lock_guard lock(mutex_);
  model->generation = current_ ? current_->generation + 1 : 1;
  current_ = std::move(model);
}

Status ModelHolder::Reload() {
  const std::shared_ptr<const LoadedModel> current = Current();
  if (!current) return Status::FailedPrecondition("no model loaded yet, nothing to reload");
  return Load(current->model_dir);
}

std::shared_ptr<const LoadedModel> ModelHolder::Current() const {
  std::lock_guard lock(mutex_);
  return current_;
}

}  // namespace tod::server
