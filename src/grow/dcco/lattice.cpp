#include "grow/dcco/lattice.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace angiosynth {

std::vector<Vec3> bifurcationLattice(const Vec3& xt, const Vec3& xp, const Vec3& xd, int delta_v, Branching b) {
  std::vector<Vec3> out;
  const int n = delta_v - 1;  // lattice steps per edge
  switch (b) {
    case Branching::None:
    case Branching::Unset: return out;
    case Branching::Distal: return {xd};
    case Branching::Fixed:
      for (int i = 1; i < n; ++i) out.push_back(xp + (xd - xp) * (double(i) / n));
      return out;
    case Branching::Versatile:
      // Barycentric (i, j, k)/n with i + j + k = n on (xp, xd, xt); corners excluded.
      for (int j = 0; j <= n; ++j)
        for (int k = 0; j + k <= n; ++k) {
          const int i = n - j - k;
          if (i == n || j == n || k == n) continue;
          out.push_back((xp * double(i) + xd * double(j) + xt * double(k)) / double(n));
        }
      return out;
  }
  return out;
}

namespace {
double angleDegrees(const Vec3& u, const Vec3& v) {
  const double c = dot(u, v) / (norm(u) * norm(v));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}
}  // namespace

double bifurcationAngle(const Vec3& b, const Vec3& xd, const Vec3& xt) { return angleDegrees(xd - b, xt - b); }

double openingAngle(const Vec3& xp, const Vec3& b, const Vec3& xd, const Vec3& xt, const Vec3& fallback_normal) {
  const Vec3 up = b - xp, down = xd - b, v = xt - b;
  Vec3 n = cross(up, down);
  if (!(norm(n) > 1e-9 * norm(up) * norm(down))) n = fallback_normal;
  if (!(norm(n) > 0)) return 90.0;
  const double c = std::abs(dot(n, v)) / (norm(n) * norm(v));
  return 90.0 - std::acos(std::clamp(c, 0.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace angiosynth
