#include "domain/demand_map.hpp"

#include <cmath>

#include "core/voxel_traversal.hpp"

namespace angiosynth {

std::int64_t DemandMap::voxelAt(const Vec3& p) const {
  const Vec3 v = toVoxel(p);
  const double fx = std::floor(v.x), fy = std::floor(v.y), fz = std::floor(v.z);
  if (fx < 0 || fy < 0 || fz < 0 || fx >= dims[0] || fy >= dims[1] || fz >= dims[2]) return -1;
  return flat(static_cast<std::int32_t>(fx), static_cast<std::int32_t>(fy), static_cast<std::int32_t>(fz));
}

bool DemandMap::segmentClear(const Vec3& a_mm, const Vec3& b_mm) const {
  const Vec3 a = toVoxel(a_mm), b = toVoxel(b_mm);
  if (!holds(a, b)) return false;
  return traverseVoxels(a, b, dims, [&](std::int32_t i, std::int32_t j, std::int32_t k) { return demand[flat(i, j, k)] > 0; });
}

}  // namespace angiosynth
