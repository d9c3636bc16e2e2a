// What every gRPC service of the server does with a call before and around its work, shared by
// the tod.v1 service (grpc_frontend.h) and the Open Inference Protocol's (oip/oip_grpc.h): the
// bearer-token check, the client's deadline on the engine's clock, why a call was cancelled, and
// a unary reactor that cancels the request's work when gRPC cancels the call.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <memory>
#include <optional>

#include "server/core/cancellation.h"
#include "server/metrics.h"
#include "server/token_auth.h"

namespace tod::server {

// UNAUTHENTICATED (logged as `method`, counted in `metrics`) when `auth` is set and the call's
// "authorization" metadata carries no valid bearer token; nullopt when the call may proceed.
std::optional<grpc::Status> RefuseUnauthenticated(const TokenAuthenticator* auth,
                                                  const grpc::CallbackServerContext& context,
                                                  const char* method, ServerMetrics& metrics);

// The client's deadline on the steady clock (nullopt when it set none).
std::optional<std::chrono::steady_clock::time_point> SteadyDeadline(
    const grpc::CallbackServerContext& context);

// Why gRPC cancelled the call: its deadline passed, or the client cancelled (or went away).
CancelReason CallCancelReason(const grpc::CallbackServerContext& context);

// A unary reactor like the default one, plus OnCancel, which stops the request's work at its
// next stage boundary. It owns itself (the callback API's model) and is deleted in OnDone, after
// Finish; the Cancellation is shared with the engine's job.
class CancellableUnaryReactor final : public grpc::ServerUnaryReactor {
 public:
  CancellableUnaryReactor(const grpc::CallbackServerContext& context,
                          std::shared_ptr<Cancellation> cancellation)
      : context_(context), cancellation_(std::move(cancellation)) {}
  void OnCancel() override { cancellation_->Cancel(CallCancelReason(context_)); }
  void OnDone() override { delete this; }

 private:
  const grpc::CallbackServerContext& context_;
  const std::shared_ptr<Cancellation> cancellation_;
};

}  // namespace tod::server
