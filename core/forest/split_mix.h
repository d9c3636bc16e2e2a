// A small, fully specified pseudo-random generator (SplitMix64). The forest's results must not
// depend on the standard library's distribution implementations, so bounded draws are done here
// (multiply-shift, Lemire) rather than with std::uniform_int_distribution.
#pragma once

#include <cstdint>

namespace tod {

class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}

  std::uint64_t Next() {
    state_ += 0x9E3779B97F4A7C15ULL;
    return Mix(state_);
  }

  // Uniform integer in [0, bound); bound > 0. The tiny bias of multiply-shift (< bound / 2^64)
  // is irrelevant for bootstrap and feature draws.
  std::uint32_t Below(std::uint32_t bound) {
    const unsigned __int128 product = static_cast<unsigned __int128>(Next()) * bound;
    return static_cast<std::uint32_t>(product >> 64);
  }

  // The SplitMix64 finaliser: a bijective 64-bit mix, also used to derive per-tree seeds.
  static std::uint64_t Mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }

 private:
  std::uint64_t state_;
};

}  // namespace tod
