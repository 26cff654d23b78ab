#pragma once
// Counter-based random numbers: a stream is a key derived from (seed, sample, stage, item),
// and draw k of a stream is a pure function of (key, k). Results therefore do not depend on
// thread count or scheduling. The mixer is SplitMix64's finaliser (passes BigCrush as a
// counter-based generator). Distributions are implemented here, not taken from <random>,
// whose distributions differ between standard libraries.
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace angiosynth {

constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Stage ids: keep stable, they are part of every output's identity.
enum class Stage : std::uint64_t { Growth = 1, Repair = 2, Raster = 3, Degrade = 4, Dataset = 5, Curves = 6 };

class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t sample, Stage stage, std::uint64_t item = 0) : key_(streamKey(seed, sample, stage) + item) {}
  // The key of item 0: fromKey(streamKey(…) + item) is Rng(…, item), for loops over many items.
  static constexpr std::uint64_t streamKey(std::uint64_t seed, std::uint64_t sample, Stage stage) {
    return mix64(mix64(mix64(seed ^ 0x6a09e667f3bcc908ULL) + sample) + static_cast<std::uint64_t>(stage));
  }

  // A stream from a key drawn from another stream (sub-streams of an effect or a voxel).
  static Rng fromKey(std::uint64_t key) { return Rng(key); }

  std::uint64_t nextU64() { return mix64(key_ + 0x9e3779b97f4a7c15ULL * ++counter_); }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(nextU64() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform in (0, 1]: safe under log().
  double uniformOpen() { return static_cast<double>((nextU64() >> 11) + 1) * 0x1.0p-53; }
  // Standard normal by Box–Muller; the second value of each pair is kept for the next call.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double r = std::sqrt(-2.0 * std::log(uniformOpen())), a = 6.283185307179586 * uniform();
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }
  std::uint64_t counter() const { return counter_; }

 private:
  explicit Rng(std::uint64_t key) : key_(key) {}
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
  double spare_ = 0;
  bool has_spare_ = false;
};

// Random access into one stream: draw i is a pure function of (key, i), for per-voxel noise
// that must not depend on which thread visits which voxel.
struct CounterStream {
  std::uint64_t key;
  std::uint64_t u64(std::uint64_t i) const { return mix64(key + 0x9e3779b97f4a7c15ULL * (i + 1)); }
  double uniform(std::uint64_t i) const { return static_cast<double>(u64(i) >> 11) * 0x1.0p-53; }
  double uniformOpen(std::uint64_t i) const { return static_cast<double>((u64(i) >> 11) + 1) * 0x1.0p-53; }
  // Two independent standard normals from draws 2i and 2i+1 (Box–Muller).
  void normalPair(std::uint64_t i, double& a, double& b) const {
    const double r = std::sqrt(-2.0 * std::log(uniformOpen(2 * i))), t = 6.283185307179586 * uniform(2 * i + 1);
    a = r * std::cos(t);
    b = r * std::sin(t);
  }
};

// FNV-1a of a name, to key streams by profile and effect names.
constexpr std::uint64_t hashName(const char* s, std::size_t n) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::size_t i = 0; i < n; ++i) h = (h ^ static_cast<unsigned char>(s[i])) * 0x100000001b3ULL;
  return h;
}

}  // namespace angiosynth
