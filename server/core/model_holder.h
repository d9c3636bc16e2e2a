// The models serving now, by name, each swapped atomically on reload. Each request takes a
// snapshot (shared_ptr) of its model when it starts, so a reload or an unload never changes the
// model under a running request.
//
// Two modes. One bundle (--model DIR): that bundle is the only model and the default; a reload
// loads its directory again. A repository (--model-repository DIR): every subdirectory of DIR
// holding a manifest.json is a model named by the directory; a reload rescans DIR, loading the
// bundles added, swapping those whose files changed and unloading those removed, each on its
// own, so that a broken bundle is refused by name while the others keep serving.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/status.h"
#include "core/pipeline/detector.h"

namespace tod::server {

struct LoadedModel {
  std::shared_ptr<const Detector> detector;
  std::string model_dir;
  int generation = 0;       // 1 for the first load of this name, +1 per successful reload
  std::string loaded_at;    // ISO 8601 UTC
  double warm_up_ms = 0;    // the warm-up detection run before it was published (warm_up.h)
  std::string fingerprint;  // the bundle's files (names, sizes, times): a change means "replaced"

  const std::string& name() const { return detector->info().name; }
};

// What a repository load or reload did, bundle by bundle.
struct RepositoryChanges {
  std::vector<std::string> loaded;                      // new names
  std::vector<std::string> swapped;                     // replaced bundles, loaded again
  std::vector<std::string> unloaded;                    // removed from the directory
  std::vector<std::pair<std::string, Status>> refused;  // broken; the previous one (if any) stays
  // OK, or the first refusal (its message names the bundle).
  Status status() const;
};

class ModelHolder {
 public:
  // One bundle: loads `model_dir` with Detector::Load and warms it up (one detection on a
  // made-up frame, so no request pays the process's one-off costs) before it becomes the only
  // model and the default; on failure the models serving stay.
  Status Load(const std::string& model_dir);
  // One bundle, already constructed (embedding, tests); `model_dir` is what Reload() reads.
  void Install(std::shared_ptr<const Detector> detector, const std::string& model_dir);

  // A repository: loads every bundle under `repository_dir` (see the top of this file). The
  // default model is `default_name` when given (refused when it is not there), else "default"
  // when there is one, else the first by name. Fails when the directory cannot be read or no
  // bundle loads.
  Result<RepositoryChanges> LoadRepository(const std::string& repository_dir,
                                           const std::string& default_name = "");

  // One bundle: its directory again. A repository: the directory rescanned.
  RepositoryChanges Reload();
  // A repository only: loads (or loads again) DIR/name, or unloads the model `name`.
  Status LoadModel(const std::string& name);
  Status UnloadModel(const std::string& name);

  // The default model, or nullptr when none is loaded.
  std::shared_ptr<const LoadedModel> Current() const;
  // The model named `name` (the default when empty), or nullptr.
  std::shared_ptr<const LoadedModel> Find(std::string_view name) const;
  // Every loaded model, by name.
  std::vector<std::shared_ptr<const LoadedModel>> Models() const;
  // The repository's bundles whose last load was refused, by name, with why (a model of that
  // name may still serve its previous load); a later load that works, or the bundle's removal
  // from the directory, takes the name off.
  std::map<std::string, Status, std::less<>> Refused() const;
  bool empty() const;
  bool repository() const;
  std::string repository_dir() const;

 private:
  // Loads and warms up a bundle outside the lock; load_mutex_ must be held.
  Result<std::shared_ptr<LoadedModel>> LoadBundle(const std::string& model_dir) const;
  // Makes `model` the one of its name with the next generation; load_mutex_ must be held.
  void Publish(std::shared_ptr<LoadedModel> model, bool only);
  // The repository's default name after a change; mutex_ must be held.
  void ChooseDefault();
  Status LoadNamed(const std::string& name, RepositoryChanges* changes);

  mutable std::mutex mutex_;  // guards the fields below; loading happens outside it
  std::mutex load_mutex_;     // one load at a time, so generations are sequential
  std::map<std::string, std::shared_ptr<const LoadedModel>, std::less<>> models_;
  std::map<std::string, int, std::less<>> generations_;  // the last generation of every name
  std::map<std::string, Status, std::less<>> refused_;
  std::string default_name_;
  std::string configured_default_;  // --default-model, empty: chosen (ChooseDefault)
  std::string repository_dir_;      // empty: one-bundle mode
};

// The fingerprint of a bundle directory (LoadedModel::fingerprint).
std::string BundleFingerprint(const std::string& model_dir);

// Current UTC time as "YYYY-MM-DDTHH:MM:SSZ".
std::string UtcNowIso8601();

}  // namespace tod::server
