#include "server/http/byte_budget.h"

#include <utility>

namespace tod::server::http {

ByteBudget::Lease::Lease(Lease&& other) noexcept
    : budget_(std::exchange(other.budget_, nullptr)), bytes_(std::exchange(other.bytes_, 0)) {}

ByteBudget::Lease& ByteBudget::Lease::operator=(Lease&& other) noexcept {
  if (this != &other) {
    if (budget_ != nullptr) budget_->Release(bytes_);
    budget_ = std::exchange(other.budget_, nullptr);
    bytes_ = std::exchange(other.bytes_, 0);
  }
  return *this;
}

ByteBudget::Lease::~Lease() {
  if (budget_ != nullptr) budget_->Release(bytes_);
}

std::optional<ByteBudget::Lease> ByteBudget::TryAcquire(uint64_t bytes) {
  std::lock_guard lock(mutex_);
  // Written as a subtraction so that no sum can overflow.
  if (bytes > capacity_ - in_use_) return std::nullopt;
  in_use_ += bytes;
  return Lease(this, bytes);
}

void ByteBudget::Release(uint64_t bytes) {
  std::lock_guard lock(mutex_);
  in_use_ -= bytes;
}

uint64_t ByteBudget::in_use() const {
  std::lock_guard lock(mutex_);
  return in_use_;
}

}  // namespace tod::server::http
