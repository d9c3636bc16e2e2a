// Explicitly seeded randomness for the synthetic generator. The distributions are written out
// here (not std::uniform_real_distribution & co., whose output differs between standard
// libraries) so a seed gives the same scene everywhere; cv::theRNG is never used.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace tod::synth {

// SplitMix64 finaliser: decorrelates nearby seeds (frame i and i + 1).
inline std::uint64_t MixSeed(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(MixSeed(seed)) {}

  std::uint64_t Bits() { return engine_(); }
  // Uniform in [0, 1) with 53 random bits.
  double Unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Unit(); }
  // Uniform integer in [lo, hi] (inclusive); the modulo bias is negligible for small ranges.
  int UniformInt(int lo, int hi) {
    if (hi <= lo) return lo;
    return lo + static_cast<int>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool Chance(double p) { return Unit() < p; }
  // Log-uniform in [lo, hi]: equal probability per octave (distances, sizes).
  double LogUniform(double lo, double hi) { return std::exp(Uniform(std::log(lo), std::log(hi))); }
  // Standard normal by Box-Muller.
  double Normal() {
    const double u1 = 1.0 - Unit();  // (0, 1]
    const double u2 = Unit();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  double Normal(double mean, double sigma) { return mean + sigma * Normal(); }
  // Child generator for an independent sub-task, so adding draws to one part of the scene does
  // not shift every later part.
  Rng Fork() { return Rng(engine_()); }
  template <typename T>
  const T& Pick(const std::vector<T>& items) {
    return items[static_cast<std::size_t>(UniformInt(0, static_cast<int>(items.size()) - 1))];
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace tod::synth
