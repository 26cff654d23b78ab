#include "domain/clear_paths.hpp"

#include <algorithm>
#include <cmath>

namespace angiosynth {

ClearPaths::ClearPaths(const DemandMap& map) : map_(map) {
  if (std::none_of(map.demand.begin(), map.demand.end(), [](float d) { return !(d > 0); })) return;
  const std::int64_t px = map.dims[0] + 2, py = map.dims[1] + 2, pz = map.dims[2] + 2;
  stride_[0] = 1;
  stride_[1] = px;
  stride_[2] = px * py;
  // The padding holds no obstacle: a segment inside the map never reaches it.
  clearance_.assign(std::size_t(px * py * pz), 255);
  for (std::int32_t k = 0; k < map.dims[2]; ++k)
    for (std::int32_t j = 0; j < map.dims[1]; ++j)
      for (std::int32_t i = 0; i < map.dims[0]; ++i)
        if (!(map.demand[std::size_t(map.flat(i, j, k))] > 0)) clearance_[std::size_t(i + 1 + (j + 1) * stride_[1] + (k + 1) * stride_[2])] = 0;
  // Two raster passes with the 26-neighbourhood at unit cost give the exact chessboard distance
  // (Rosenfeld & Pfaltz 1966): the forward pass looks at the 13 neighbours already visited.
  std::int64_t before[13];
  int n = 0;
  for (int dk = -1; dk <= 0; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const std::int64_t o = di + dj * stride_[1] + dk * stride_[2];
        if (o < 0) before[n++] = o;
      }
  const auto relax = [&](std::int64_t v, int sign) {
    int d = clearance_[std::size_t(v)];
    for (const auto o : before) d = std::min(d, clearance_[std::size_t(v + sign * o)] + 1);
    clearance_[std::size_t(v)] = static_cast<std::uint8_t>(d);
  };
  for (std::int64_t k = 1; k < pz - 1; ++k)
    for (std::int64_t j = 1; j < py - 1; ++j)
      for (std::int64_t i = 1; i < px - 1; ++i) relax(i + j * stride_[1] + k * stride_[2], 1);
  for (std::int64_t k = pz - 2; k >= 1; --k)
    for (std::int64_t j = py - 2; j >= 1; --j)
      for (std::int64_t i = px - 2; i >= 1; --i) relax(i + j * stride_[1] + k * stride_[2], -1);
}

bool ClearPaths::segmentClear(const Vec3& a_mm, const Vec3& b_mm) const {
  const Vec3 a = map_.toVoxel(a_mm), b = map_.toVoxel(b_mm);
  if (map_.holds(a, b)) {
    if (clearance_.empty()) return true;
    // The voxels walked from a to b lie within ceil(|b − a|∞) of a's voxel along every axis.
    const double reach = std::max({std::abs(b.x - a.x), std::abs(b.y - a.y), std::abs(b.z - a.z)});
    std::int64_t v = 0;
    for (int ax = 0; ax < 3; ++ax) v += (std::min(static_cast<std::int64_t>(std::floor(a[ax])), std::int64_t(map_.dims[ax] - 1)) + 1) * stride_[ax];
    if (double(clearance_[std::size_t(v)]) > reach + 1) return true;
  }
  return map_.segmentClear(a_mm, b_mm);
}

}  // namespace angiosynth
