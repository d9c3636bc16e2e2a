// Caps open HTTP connections in total and per client address. A connection holds a ticket for its
// whole life; the ticket's destructor gives the slot back, so no path can leak one. The limiter
// must outlive its tickets (the HTTP server owns both and destroys its connections first).
#pragma once

#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "server/http/refusal.h"

namespace tod::server::http {

class ConnectionLimiter {
 public:
  class Ticket {
   public:
    Ticket() = default;  // holds no slot
    Ticket(Ticket&& other) noexcept;
    Ticket& operator=(Ticket&& other) noexcept;
    Ticket(const Ticket&) = delete;
    Ticket& operator=(const Ticket&) = delete;
    ~Ticket();

   private:
    friend class ConnectionLimiter;
    Ticket(ConnectionLimiter* limiter, std::string client)
        : limiter_(limiter), client_(std::move(client)) {}
    ConnectionLimiter* limiter_ = nullptr;
    std::string client_;
  };

  // A ticket for one more connection from `client`, or the reason there is none.
  struct Admission {
    Ticket ticket;
    std::optional<RefusalReason> refused;
  };

  // `on_change` (may be empty) gets the number of open connections after every change.
  ConnectionLimiter(int max_total, int max_per_client, std::function<void(int)> on_change);
  ConnectionLimiter(const ConnectionLimiter&) = delete;
  ConnectionLimiter& operator=(const ConnectionLimiter&) = delete;

  Admission TryAcquire(const std::string& client);
  int open() const;

 private:
  void Release(const std::string& client);

  const int max_total_;
  const int max_per_client_;
  const std::function<void(int)> on_change_;
  mutable std::mutex mutex_;  // guards the counts
  int open_ = 0;
  std::map<std::string, int> per_client_;  // only clients with open connections
};

}  // namespace tod::server::http
