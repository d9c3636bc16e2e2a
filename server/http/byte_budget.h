// A shared budget of request-body bytes. Each connection charges what its request may buffer
// before the body is read (the declared length, or the body limit for a chunked body) and gives
// it back when the response is written, so many connections together cannot exhaust memory
// even when each stays under the per-request body limit.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>

namespace tod::server::http {

class ByteBudget {
 public:
  class Lease {
   public:
    Lease() = default;  // holds no bytes
    Lease(Lease&& other) noexcept;
    Lease& operator=(Lease&& other) noexcept;
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    ~Lease();
    uint64_t bytes() const { return bytes_; }

   private:
    friend class ByteBudget;
    Lease(ByteBudget* budget, uint64_t bytes) : budget_(budget), bytes_(bytes) {}
    ByteBudget* budget_ = nullptr;
    uint64_t bytes_ = 0;
  };

  explicit ByteBudget(uint64_t capacity) : capacity_(capacity) {}
  ByteBudget(const ByteBudget&) = delete;
  ByteBudget& operator=(const ByteBudget&) = delete;

  // A lease of `bytes`, or nullopt when the budget cannot cover them now.
  std::optional<Lease> TryAcquire(uint64_t bytes);
  uint64_t in_use() const;

 private:
  void Release(uint64_t bytes);

  const uint64_t capacity_;
  mutable std::mutex mutex_;  // guards in_use_
  uint64_t in_use_ = 0;
};

}  // namespace tod::server::http
