#pragma once
// Counter-based random numbers: a stream is a key derived from (seed, sample, stage, item),
// and draw k of a stream is a pure function of (key, k). Results therefore do not depend on
// thread count or scheduling. The mixer is SplitMix64's finaliser (passes BigCrush as a
// counter-based generator). Distributions are implemented here, not taken from <random>,
// whose distributions differ between standard libraries.
#include <cmath>
#include <cstdint>

namespace angiosynth {

constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Stage ids: keep stable, they are part of every output's identity.
enum class Stage : std::uint64_t { Growth = 1, Repair = 2, Raster = 3, Degrade = 4, Dataset = 5 };

class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t sample, Stage stage, std::uint64_t item = 0)
      : key_(mix64(mix64(mix64(seed ^ 0x6a09e667f3bcc908ULL) + sample) +
                   static_cast<std::uint64_t>(stage)) + item) {}

  std::uint64_t nextU64() { return mix64(key_ + 0x9e3779b97f4a7c15ULL * ++counter_); }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(nextU64() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  std::uint64_t counter() const { return counter_; }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
};

}  // namespace angiosynth
