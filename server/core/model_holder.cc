#include "server/core/model_holder.h"

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <set>

#include "core/pipeline/warm_up.h"

namespace tod::server {
namespace fs = std::filesystem;

namespace {

constexpr char kManifest[] = "manifest.json";

// The names of the bundle directories under `repository_dir`, sorted; hidden entries (and the
// temporary directories a bundle writer renames into place) are skipped.
Result<std::set<std::string>> BundleNames(const std::string& repository_dir) {
  std::error_code error;
  fs::directory_iterator entries(repository_dir, error);
  if (error) {
    return Status::NotFound("cannot read the model repository " + repository_dir + ": " +
                            error.message());
  }
  std::set<std::string> names;
  for (const fs::directory_entry& entry : entries) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.front() == '.' || name.find(".tmp") != std::string::npos) continue;
    if (entry.is_directory(error) && fs::exists(entry.path() / kManifest, error)) {
      names.insert(name);
    }
  }
  return names;
}

}  // namespace

std::string UtcNowIso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::string BundleFingerprint(const std::string& model_dir) {
  std::error_code error;
  std::vector<std::string> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(model_dir, error)) {
    if (!entry.is_regular_file(error)) continue;
    const auto size = entry.file_size(error);
    const auto written = entry.last_write_time(error).time_since_epoch().count();
    files.push_back(entry.path().filename().string() + ":" + std::to_string(size) + ":" +
                    std::to_string(written));
  }
  std::sort(files.begin(), files.end());
  std::string fingerprint;
  for (const std::string& file : files) fingerprint += file + ";";
  return fingerprint;
}

Status RepositoryChanges::status() const {
  if (refused.empty()) return Status::Ok();
  return refused.front().second.WithContext("model '" + refused.front().first + "'");
}

Result<std::shared_ptr<LoadedModel>> ModelHolder::LoadBundle(const std::string& model_dir) const {
  // Taken before loading: a bundle replaced while it loads then differs from it at the next
  // reload, and is loaded again.
  std::string fingerprint = BundleFingerprint(model_dir);
  Result<std::shared_ptr<const Detector>> detector = Detector::Load(model_dir);
  if (!detector.ok()) return detector.status();
  if (*detector == nullptr) return Status::Internal("model loader returned no detector");
  const Result<double> warm_up_ms = WarmUp(**detector);
  if (!warm_up_ms.ok()) return warm_up_ms.status().WithContext(model_dir);
  auto model = std::make_shared<LoadedModel>();
  model->detector = std::move(*detector);
  model->model_dir = model_dir;
  model->warm_up_ms = *warm_up_ms;
  model->fingerprint = std::move(fingerprint);
  return model;
}

void ModelHolder::Publish(std::shared_ptr<LoadedModel> model, bool only) {
  model->loaded_at = UtcNowIso8601();
  std::lock_guard lock(mutex_);
  model->generation = ++generations_[model->name()];
  if (only) {
    models_.clear();
    default_name_ = model->name();
  }
  models_[model->name()] = std::move(model);
  if (!only) ChooseDefault();
}

void ModelHolder::ChooseDefault() {
  if (!configured_default_.empty()) {
    default_name_ = configured_default_;
  } else if (models_.count("default") > 0) {
    default_name_ = "default";
  } else {
    default_name_ = models_.empty() ? "" : models_.begin()->first;
  }
}

Status ModelHolder::Load(const std::string& model_dir) {
  std::lock_guard load_lock(load_mutex_);
  Result<std::shared_ptr<LoadedModel>> model = LoadBundle(model_dir);
  if (!model.ok()) return model.status();
  {
    std::lock_guard lock(mutex_);
    repository_dir_.clear();
    configured_default_.clear();
  }
  Publish(std::move(*model), /*only=*/true);
  return Status::Ok();
}

void ModelHolder::Install(std::shared_ptr<const Detector> detector, const std::string& model_dir) {
  std::lock_guard load_lock(load_mutex_);
  auto model = std::make_shared<LoadedModel>();
  model->detector = std::move(detector);
  model->model_dir = model_dir;
  {
    std::lock_guard lock(mutex_);
    repository_dir_.clear();
  }
  Publish(std::move(model), /*only=*/true);
}

Status ModelHolder::LoadNamed(const std::string& name, RepositoryChanges* changes) {
  const std::string dir = (fs::path(repository_dir()) / name).string();
  const std::shared_ptr<const LoadedModel> previous = Find(name);
  Result<std::shared_ptr<LoadedModel>> model = LoadBundle(dir);
  if (!model.ok()) {
    changes->refused.emplace_back(name, model.status());
    std::lock_guard lock(mutex_);
    refused_.insert_or_assign(name, model.status());
    return model.status();
  }
  {
    std::lock_guard lock(mutex_);
    refused_.erase(name);
  }
  (previous ? changes->swapped : changes->loaded).push_back(name);
  Publish(std::move(*model), /*only=*/false);
  return Status::Ok();
}

Result<RepositoryChanges> ModelHolder::LoadRepository(const std::string& repository_dir,
                                                      const std::string& default_name) {
  {
    std::lock_guard load_lock(load_mutex_);
    const Result<std::set<std::string>> names = BundleNames(repository_dir);
    if (!names.ok()) return names.status();
    if (!default_name.empty() && names->count(default_name) == 0) {
      return Status::NotFound("the default model '" + default_name + "' is not a bundle in " +
                              repository_dir);
    }
    std::lock_guard lock(mutex_);
    models_.clear();
    refused_.clear();
    repository_dir_ = repository_dir;
    configured_default_ = default_name;
  }
  RepositoryChanges changes = Reload();
  if (empty()) {
    const Status first = changes.status();
    return Status::FailedPrecondition("no bundle in the model repository " + repository_dir +
                                      " loads" + (first.ok() ? "" : ": " + first.message()));
  }
  return changes;
}

RepositoryChanges ModelHolder::Reload() {
  RepositoryChanges changes;
  if (!repository()) {
    const std::shared_ptr<const LoadedModel> current = Current();
    if (!current) {
      changes.refused.emplace_back(
          "", Status::FailedPrecondition("no model loaded yet, nothing to reload"));
    } else if (Status loaded = Load(current->model_dir); !loaded.ok()) {
      changes.refused.emplace_back(current->name(), loaded);
    } else {
      changes.swapped.push_back(current->name());
    }
    return changes;
  }
  std::lock_guard load_lock(load_mutex_);
  const Result<std::set<std::string>> names = BundleNames(repository_dir());
  if (!names.ok()) {
    changes.refused.emplace_back("", names.status());
    return changes;
  }
  {
    std::lock_guard lock(mutex_);
    std::erase_if(refused_, [&](const auto& entry) { return names->count(entry.first) == 0; });
  }
  for (const std::shared_ptr<const LoadedModel>& model : Models()) {
    if (names->count(model->name()) > 0) continue;
    std::lock_guard lock(mutex_);
    models_.erase(model->name());
    changes.unloaded.push_back(model->name());
    ChooseDefault();
  }
  for (const std::string& name : *names) {
    const std::shared_ptr<const LoadedModel> current = Find(name);
    if (current &&
        current->fingerprint == BundleFingerprint((fs::path(repository_dir()) / name).string())) {
      continue;  // unchanged
    }
    // A refusal is recorded in `changes`; the other bundles load regardless.
    static_cast<void>(LoadNamed(name, &changes));
  }
  return changes;
}

Status ModelHolder::LoadModel(const std::string& name) {
  if (!repository()) {
    return Status::FailedPrecondition("the server serves one bundle (--model), not a repository");
  }
  if (name.empty() || name.front() == '.' || name.find('/') != std::string::npos) {
    return Status::InvalidArgument("'" + name + "' is not a bundle name");
  }
  std::lock_guard load_lock(load_mutex_);
  std::error_code error;
  const fs::path dir = fs::path(repository_dir()) / name;
  if (!fs::exists(dir / kManifest, error)) {
    return Status::NotFound("no bundle '" + name + "' in the model repository");
  }
  RepositoryChanges changes;
  return LoadNamed(name, &changes);
}

Status ModelHolder::UnloadModel(const std::string& name) {
  if (!repository()) {
    return Status::FailedPrecondition("the server serves one bundle (--model), not a repository");
  }
  std::lock_guard load_lock(load_mutex_);
  std::lock_guard lock(mutex_);
  if (models_.erase(name) == 0) return Status::NotFound("unknown model '" + name + "'");
  ChooseDefault();
  return Status::Ok();
}

std::shared_ptr<const LoadedModel> ModelHolder::Current() const { return Find(""); }

std::shared_ptr<const LoadedModel> ModelHolder::Find(std::string_view name) const {
  std::lock_guard lock(mutex_);
  const auto it = models_.find(name.empty() ? std::string_view(default_name_) : name);
  return it == models_.end() ? nullptr : it->second;
}

std::vector<std::shared_ptr<const LoadedModel>> ModelHolder::Models() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<const LoadedModel>> models;
  for (const auto& [name, model] : models_) models.push_back(model);
  return models;
}

std::map<std::string, Status, std::less<>> ModelHolder::Refused() const {
  std::lock_guard lock(mutex_);
  return refused_;
}

bool ModelHolder::empty() const {
  std::lock_guard lock(mutex_);
  return models_.empty();
}

bool ModelHolder::repository() const {
  std::lock_guard lock(mutex_);
  return !repository_dir_.empty();
}

std::string ModelHolder::repository_dir() const {
  std::lock_guard lock(mutex_);
  return repository_dir_;
}

}  // namespace tod::server
