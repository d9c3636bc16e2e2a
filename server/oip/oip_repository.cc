#include "server/oip/oip_repository.h"

#include <nlohmann/json.hpp>

#include "server/http/percent_decoding.h"
#include "server/oip/oip_errors.h"
#include "server/oip/oip_model.h"

namespace tod::server::oip {
namespace {

using http::beast_http::field;
using http::beast_http::verb;
using nlohmann::json;

constexpr const char* kJson = kJsonType;

// "/v2/repository/models/{name}/{load|unload}" -> name and action; nullopt for other paths.
struct ModelCall {
  std::string name;
  std::string action;
};
std::optional<ModelCall> ParseModelCall(std::string_view path) {
  constexpr std::string_view kModels = "/v2/repository/models/";
  if (!path.starts_with(kModels)) return std::nullopt;
  path.remove_prefix(kModels.size());
  const size_t slash = path.find('/');
  if (slash == std::string_view::npos) return std::nullopt;
  const std::optional<std::string> name = http::DecodePathSegment(path.substr(0, slash));
  const std::string_view action = path.substr(slash + 1);
  if (!name || name->empty() || (action != "load" && action != "unload")) return std::nullopt;
  return ModelCall{*name, std::string(action)};
}

}  // namespace

OipRepositoryApi::OipRepositoryApi(ModelHolder& models,
                                   std::shared_ptr<const TokenAuthenticator> admin,
                                   std::function<void(const RepositoryChanges&)> on_change)
    : models_(models), admin_(std::move(admin)), on_change_(std::move(on_change)) {}

OipRepositoryApi::~OipRepositoryApi() {
  std::lock_guard lock(loader_mutex_);
  if (loader_.joinable()) loader_.join();
}

void OipRepositoryApi::AddRoutes(http::Router* router) {
  router->AddPrefix(
      verb::post, std::string(kRepositoryPrefix),
      [this](http::IncomingRequest request, http::Responder respond) { Handle(request, respond); });
}

void OipRepositoryApi::Handle(const http::IncomingRequest& request,
                              const http::Responder& respond) {
  if (!admin_) {
    respond(OipError(403,
                     "the model repository calls are off: start tod_server with "
                     "--model-repository DIR --admin-token-file FILE"));
    return;
  }
  if (const std::optional<std::string> refused =
          admin_->Check(request.message[field::authorization])) {
    http::Response response = OipError(401, *refused);
    response.set(field::www_authenticate, "Bearer");
    respond(std::move(response));
    return;
  }
  const std::string_view path = http::TargetPath(request.message.target());
  if (path == "/v2/repository/index") {
    json index = json::array();
    const auto refused = models_.Refused();
    for (const std::shared_ptr<const LoadedModel>& model : models_.Models()) {
      json entry = {{"name", model->name()},
                    {"version", ModelVersion(model->detector->info())},
                    {"state", "READY"}};
      // Serving its previous load: say why the last one was refused.
      if (const auto it = refused.find(model->name()); it != refused.end()) {
        entry["reason"] = it->second.ToString();
      }
      index.push_back(std::move(entry));
    }
    for (const auto& [name, status] : refused) {
      if (models_.Find(name) == nullptr) {
        index.push_back({{"name", name}, {"state", "UNAVAILABLE"}, {"reason", status.ToString()}});
      }
    }
    respond(http::ContentResponse(Dump(index), kJson));
    return;
  }
  const std::optional<ModelCall> call = ParseModelCall(path);
  if (!call) {
    respond(OipError(404, "no such endpoint: " + std::string(path)));
    return;
  }
  if (call->action == "load") {
    Load(call->name, respond);
    return;
  }
  const Status unloaded = models_.UnloadModel(call->name);
  if (!unloaded.ok()) {
    respond(OipError(unloaded));
    return;
  }
  RepositoryChanges changes;
  changes.unloaded.push_back(call->name);
  on_change_(changes);
  respond(http::ContentResponse("{}", kJson));
}

void OipRepositoryApi::Load(const std::string& name, const http::Responder& respond) {
  std::lock_guard lock(loader_mutex_);
  if (loading_) {
    respond(OipError(409, "a model is loading; retry when it is done"));
    return;
  }
  if (loader_.joinable()) loader_.join();  // the previous load, finished
  loading_ = true;
  loader_ = std::thread([this, name, respond] {
    const bool existed = models_.Find(name) != nullptr;
    const Status loaded = models_.LoadModel(name);
    RepositoryChanges changes;
    if (loaded.ok()) {
      (existed ? changes.swapped : changes.loaded).push_back(name);
    } else {
      changes.refused.emplace_back(name, loaded);
    }
    on_change_(changes);
    {
      std::lock_guard done(loader_mutex_);
      loading_ = false;
    }
    respond(loaded.ok() ? http::ContentResponse("{}", kJson) : OipError(loaded));
  });
}

}  // namespace tod::server::oip
