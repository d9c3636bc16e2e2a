// Helpers shared by the fuzz targets.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

namespace tod::fuzz {

// An invariant the fuzzer must not be able to break: abort, so libFuzzer saves the input.
inline void Check(bool condition) {
  if (!condition) std::abort();
}

// Takes the fuzzer's bytes from the front; past the end every value is 0, so any input is usable.
class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint8_t U8() { return at_ < size_ ? data_[at_++] : 0; }
  size_t left() const { return size_ - at_; }
  const uint8_t* rest() const { return data_ + at_; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

}  // namespace tod::fuzz
