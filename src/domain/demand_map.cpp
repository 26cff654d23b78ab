#include "domain/demand_map.hpp"

#include <cmath>
#include <limits>

namespace angiosynth {

std::int64_t DemandMap::voxelAt(const Vec3& p) const {
  const Vec3 v = toVoxel(p);
  const double fx = std::floor(v.x), fy = std::floor(v.y), fz = std::floor(v.z);
  if (fx < 0 || fy < 0 || fz < 0 || fx >= dims[0] || fy >= dims[1] || fz >= dims[2]) return -1;
  return flat(static_cast<std::int32_t>(fx), static_cast<std::int32_t>(fy), static_cast<std::int32_t>(fz));
}

bool DemandMap::segmentClear(const Vec3& a_mm, const Vec3& b_mm) const {
  // Voxel traversal (Amanatides & Woo 1987): visits every voxel the line passes through.
  const Vec3 a = toVoxel(a_mm), b = toVoxel(b_mm);
  const Vec3 d = b - a;
  std::int32_t cell[3], step[3], last[3];
  double t_max[3], t_delta[3];
  for (int ax = 0; ax < 3; ++ax) {
    const double pa = a[ax], pb = b[ax];
    if (pa < 0 || pb < 0 || pa > dims[ax] || pb > dims[ax]) return false;
    cell[ax] = std::min(static_cast<std::int32_t>(std::floor(pa)), dims[ax] - 1);
    last[ax] = std::min(static_cast<std::int32_t>(std::floor(pb)), dims[ax] - 1);
    const double da = d[ax];
    step[ax] = da > 0 ? 1 : (da < 0 ? -1 : 0);
    if (step[ax] == 0) {
      t_max[ax] = t_delta[ax] = std::numeric_limits<double>::infinity();
    } else {
      const double boundary = step[ax] > 0 ? cell[ax] + 1.0 : static_cast<double>(cell[ax]);
      t_max[ax] = (boundary - pa) / da;
      t_delta[ax] = std::abs(1.0 / da);
    }
  }
  for (int guard = 0; guard < 4 * (dims[0] + dims[1] + dims[2]) + 8; ++guard) {
    if (demand[flat(cell[0], cell[1], cell[2])] <= 0) return false;
    if (cell[0] == last[0] && cell[1] == last[1] && cell[2] == last[2]) return true;
    const int ax = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    if (t_max[ax] > 1.0) return true;  // reached b (rounding at the end cell)
    cell[ax] += step[ax];
    if (cell[ax] < 0 || cell[ax] >= dims[ax]) return true;  // b lies on the far map boundary
    t_max[ax] += t_delta[ax];
  }
  return true;
}

}  // namespace angiosynth
