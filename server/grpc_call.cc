#include "server/grpc_call.h"

#include <string>
#include <string_view>

#include "server/logging.h"

namespace tod::server {

std::optional<grpc::Status> RefuseUnauthenticated(const TokenAuthenticator* auth,
                                                  const grpc::CallbackServerContext& context,
                                                  const char* method, ServerMetrics& metrics) {
  if (!auth) return std::nullopt;
  const auto& metadata = context.client_metadata();
  const auto header = metadata.find("authorization");
  const std::string_view value =
      header == metadata.end() ? std::string_view()
                               : std::string_view(header->second.data(), header->second.size());
  const std::optional<std::string> refused = auth->Check(value);
  if (!refused) return std::nullopt;
  metrics.RecordRejection("unauthenticated");
  metrics.RecordRequest("grpc", "UNAUTHENTICATED", 0);
  LogEvent(
      spdlog::level::warn, "unauthenticated",
      {{"protocol", "grpc"}, {"method", method}, {"peer", context.peer()}, {"error", *refused}});
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, *refused);
}

std::optional<std::chrono::steady_clock::time_point> SteadyDeadline(
    const grpc::CallbackServerContext& context) {
  // gRPC reports the deadline on the system clock; the engine works on the steady clock.
  const auto deadline = context.deadline();
  if (deadline >= std::chrono::system_clock::time_point::max() - std::chrono::hours(24 * 365)) {
    return std::nullopt;  // no deadline set
  }
  const auto remaining = deadline - std::chrono::system_clock::now();
  return std::chrono::steady_clock::now() +
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(remaining);
}

CancelReason CallCancelReason(const grpc::CallbackServerContext& context) {
  // The client's own deadline timer fires before the server's (the server counts from when the
  // request arrived), and its cancellation then reaches the server first; so a cancellation this
  // close to the deadline is the deadline's.
  constexpr std::chrono::seconds kDeadlineSlack(1);
  return context.deadline() - kDeadlineSlack <= std::chrono::system_clock::now()
             ? CancelReason::kDeadline
             : CancelReason::kClientCancelled;
}

}  // namespace tod::server
