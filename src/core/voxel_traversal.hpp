#pragma once
// Every voxel a straight line passes through (Amanatides & Woo 1987). Coordinates are in voxel
// units where voxel i covers [i, i+1); both ends must lie in [0, dims]. Calls f(i, j, k) in
// order from a to b; stops early when f returns false. Returns false if stopped early.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/vec3.hpp"

namespace angiosynth {

template <class F>
bool traverseVoxels(const Vec3& a, const Vec3& b, const std::array<std::int32_t, 3>& dims, F&& f) {
  const Vec3 d = b - a;
  std::int32_t cell[3], step[3], last[3];
  double t_max[3], t_delta[3];
  for (int ax = 0; ax < 3; ++ax) {
    cell[ax] = std::min(static_cast<std::int32_t>(std::floor(a[ax])), dims[ax] - 1);
    last[ax] = std::min(static_cast<std::int32_t>(std::floor(b[ax])), dims[ax] - 1);
    const double da = d[ax];
    step[ax] = da > 0 ? 1 : (da < 0 ? -1 : 0);
    if (step[ax] == 0) {
      t_max[ax] = t_delta[ax] = std::numeric_limits<double>::infinity();
    } else {
      const double boundary = step[ax] > 0 ? cell[ax] + 1.0 : static_cast<double>(cell[ax]);
      t_max[ax] = (boundary - a[ax]) / da;
      t_delta[ax] = std::abs(1.0 / da);
    }
  }
  for (int guard = 0; guard < 4 * (dims[0] + dims[1] + dims[2]) + 8; ++guard) {
    if (!f(cell[0], cell[1], cell[2])) return false;
    if (cell[0] == last[0] && cell[1] == last[1] && cell[2] == last[2]) return true;
    const int ax = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    if (t_max[ax] > 1.0) return true;  // reached b (rounding at the end cell)
    cell[ax] += step[ax];
    if (cell[ax] < 0 || cell[ax] >= dims[ax]) return true;  // b lies on the far boundary
    t_max[ax] += t_delta[ax];
  }
  return true;
}

}  // namespace angiosynth
