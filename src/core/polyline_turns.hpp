#pragma once
// The turning of a polyline, as Bullitt et al. (2003) measure a vessel's tortuosity: the count of
// inflections (the turning direction flips) and the sum of the angles at its interior points
// (in-plane and torsion angles combined). Shared by `stats` and the curves that aim at it.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

struct PolylineTurns {
  int inflections = 0;
  double total_angle = 0;  // rad
};

inline PolylineTurns polylineTurns(const std::vector<Vec3>& p) {
  PolylineTurns out;
  std::vector<Vec3> d, b;
  for (std::size_t k = 1; k < p.size(); ++k) d.push_back(unit(p[k] - p[k - 1]));
  for (std::size_t k = 0; k + 1 < d.size(); ++k) {
    const Vec3 n = cross(d[k], d[k + 1]);
    b.push_back(norm(n) > 1e-12 ? unit(n) : Vec3(0, 0, 0));
  }
  for (std::size_t k = 0; k < b.size(); ++k) {
    const double in_plane = std::acos(std::clamp(dot(d[k], d[k + 1]), -1.0, 1.0));
    double torsion = 0;
    if (k + 1 < b.size() && norm(b[k]) > 0 && norm(b[k + 1]) > 0) {
      const double c = dot(b[k], b[k + 1]);
      torsion = std::acos(std::clamp(c, -1.0, 1.0));
      out.inflections += c < 0;
      // A flip of the turning direction is an inflection, not torsion.
      if (c < 0) torsion = std::numbers::pi - torsion;
    }
    out.total_angle += std::sqrt(in_plane * in_plane + torsion * torsion);
  }
  return out;
}

}  // namespace angiosynth
