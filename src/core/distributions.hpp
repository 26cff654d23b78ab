#pragma once
// Distributions beyond the uniform and normal of Rng, written out so that every platform draws
// the same numbers (std::poisson_distribution differs between standard libraries).
#include <cmath>
#include <cstdint>

#include "core/rng.hpp"
#include "core/vec3.hpp"

namespace angiosynth {

// A point uniform in [lo, hi)^3, or in [lo, hi)^2 at z = flat_z when `flat`. The coordinates
// are drawn z, y, x in turn: written as three arguments of one call they were unsequenced
// (GCC drew right to left, Clang left to right, giving different trees); this fixes GCC's order
// so that trees grown before stay as they were.
inline Vec3 uniformPoint(Rng& rng, double lo, double hi, bool flat = false, double flat_z = 0) {
  const double z = flat ? flat_z : rng.uniform(lo, hi);
  const double y = rng.uniform(lo, hi);
  const double x = rng.uniform(lo, hi);
  return Vec3(x, y, z);
}

// Poisson(λ): Knuth's product of uniforms below λ = 10 (a dozen draws at most on average), and
// Hörmann's transformed rejection with squeeze (PTRS, 1993) above, whose cost does not grow
// with λ. Exact in distribution for every λ >= 0.
inline std::int64_t poisson(double lambda, Rng& rng) {
  if (!(lambda > 0)) return 0;
  if (lambda < 10) {
    const double limit = std::exp(-lambda);
    double prod = rng.uniform();
    std::int64_t k = 0;
    while (prod > limit) {
      prod *= rng.uniform();
      ++k;
    }
    return k;
  }
  const double slam = std::sqrt(lambda), loglam = std::log(lambda);
  const double b = 0.931 + 2.53 * slam, a = -0.059 + 0.02483 * b;
  const double inv_alpha = 1.1239 + 1.1328 / (b - 3.4), vr = 0.9277 - 3.6224 / (b - 2);
  for (;;) {
    const double u = rng.uniform() - 0.5, v = rng.uniform();
    const double us = 0.5 - std::fabs(u);
    const double k = std::floor((2 * a / us + b) * u + lambda + 0.43);
    if (us >= 0.07 && v <= vr) return static_cast<std::int64_t>(k);
    if (k < 0 || (us < 0.013 && v > us)) continue;
    if (std::log(v) + std::log(inv_alpha) - std::log(a / (us * us) + b) <= -lambda + k * loglam - std::lgamma(k + 1))
      return static_cast<std::int64_t>(k);
  }
}

}  // namespace angiosynth
