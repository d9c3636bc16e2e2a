#include "server/http/connection_limiter.h"

#include <utility>

namespace tod::server::http {

ConnectionLimiter::Ticket::Ticket(Ticket&& other) noexcept
    : limiter_(std::exchange(other.limiter_, nullptr)), client_(std::move(other.client_)) {}

ConnectionLimiter::Ticket& ConnectionLimiter::Ticket::operator=(Ticket&& other) noexcept {
  if (this != &other) {
    if (limiter_ != nullptr) limiter_->Release(client_);
    limiter_ = std::exchange(other.limiter_, nullptr);
    client_ = std::move(other.client_);
  }
  return *this;
}

ConnectionLimiter::Ticket::~Ticket() {
  if (limiter_ != nullptr) limiter_->Release(client_);
}

ConnectionLimiter::ConnectionLimiter(int max_total, int max_per_client,
                                     std::function<void(int)> on_change)
    : max_total_(max_total), max_per_client_(max_per_client), on_change_(std::move(on_change)) {}

ConnectionLimiter::Admission ConnectionLimiter::TryAcquire(const std::string& client) {
  int open = 0;
  {
    std::lock_guard lock(mutex_);
    if (open_ >= max_total_) return {Ticket(), RefusalReason::kTooManyConnections};
    int& from_client = per_client_[client];
    if (from_client >= max_per_client_) {
      if (from_client == 0) per_client_.erase(client);
      return {Ticket(), RefusalReason::kTooManyConnectionsPerClient};
    }
    ++from_client;
    open = ++open_;
  }
  if (on_change_) on_change_(open);
  return {Ticket(this, client), std::nullopt};
}

void ConnectionLimiter::Release(const std::string& client) {
  int open = 0;
  {
    std::lock_guard lock(mutex_);
    if (auto it = per_client_.find(client); it != per_client_.end() && --it->second <= 0) {
      per_client_.erase(it);
    }
    open = --open_;
  }
  if (on_change_) on_change_(open);
}

int ConnectionLimiter::open() const {
  std::lock_guard lock(mutex_);
  return open_;
}

}  // namespace tod::server::http
