// The Open Inference Protocol's model repository extension, for a server started with
// --model-repository and --admin-token-file:
//
//   POST /v2/repository/index                         the bundles: name, version, state READY
//                                                     (serving) or UNAVAILABLE (refused; reason)
//   POST /v2/repository/models/{name}/load            (re)load DIR/{name}: 200 {} when serving
//   POST /v2/repository/models/{name}/unload          stop serving it: 200 {}
//
// Every call needs "authorization: Bearer <admin token>" (the --admin-token-file tokens, not the
// API's): loading code paths from disk is an operator's act. Without an admin token file the
// calls are 403. A load runs on this API's own thread (a bundle loads and warms up in seconds,
// which must not hold an HTTP I/O thread), one at a time: a second while one runs is 409.
// Requests to the other models are served throughout.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <thread>

#include "server/core/model_holder.h"
#include "server/http/router.h"
#include "server/token_auth.h"

namespace tod::server::oip {

inline constexpr std::string_view kRepositoryPrefix = "/v2/repository/";

class OipRepositoryApi {
 public:
  // `models` must outlive the API. `admin` null: the calls are refused (403). `on_change` is told
  // what a load or unload did (metrics, log); it may run on the loader thread.
  OipRepositoryApi(ModelHolder& models, std::shared_ptr<const TokenAuthenticator> admin,
                   std::function<void(const RepositoryChanges&)> on_change);
  ~OipRepositoryApi();  // waits for a load in progress
  OipRepositoryApi(const OipRepositoryApi&) = delete;
  OipRepositoryApi& operator=(const OipRepositoryApi&) = delete;

  void AddRoutes(http::Router* router);

 private:
  void Handle(const http::IncomingRequest& request, const http::Responder& respond);
  void Load(const std::string& name, const http::Responder& respond);

  ModelHolder& models_;
  const std::shared_ptr<const TokenAuthenticator> admin_;
  const std::function<void(const RepositoryChanges&)> on_change_;
  std::mutex loader_mutex_;  // guards loader_ and loading_
  std::thread loader_;
  bool loading_ = false;
};

}  // namespace tod::server::oip
