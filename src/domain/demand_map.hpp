#pragma once
// The oxygen-demand map (Hamarneh & Jassi 2010 §3.2) and the supply coefficients (§3.10) on one voxel grid.
// Map voxel (i,j,k) covers [i,i+1)×[j,j+1)×[k,k+1) in map-voxel coordinates; position in mm
// = map-voxel coordinate × voxel_mm, origin at the corner of voxel (0,0,0).
#include <array>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

struct DemandMap {
  std::array<std::int32_t, 3> dims{0, 0, 0};
  double voxel_mm = 1;
  std::vector<float> demand;  // initial demand; 0 = obstacle no vessel may cross
  // Supply coefficients per voxel: index into supply_sets; a set's last value is the cut-off
  // radius (map voxels). An empty set means "no reduction" (voxel not covered by a supply box).
  std::vector<std::uint16_t> supply_index;
  std::vector<std::vector<double>> supply_sets;

  std::int64_t voxelCount() const { return std::int64_t(dims[0]) * dims[1] * dims[2]; }
  std::int64_t flat(std::int32_t i, std::int32_t j, std::int32_t k) const { return i + std::int64_t(dims[0]) * (j + std::int64_t(dims[1]) * k); }
  Vec3 extentMm() const { return Vec3(dims[0], dims[1], dims[2]) * voxel_mm; }
  Vec3 toVoxel(const Vec3& mm) const { return mm / voxel_mm; }
  Vec3 toMm(const Vec3& vox) const { return vox * voxel_mm; }
  // Flat index of the voxel containing p (mm), or -1 outside the map.
  std::int64_t voxelAt(const Vec3& p_mm) const;
  // True if p lies in the map on a voxel of non-zero initial demand.
  bool perfusable(const Vec3& p_mm) const {
    const auto v = voxelAt(p_mm);
    return v >= 0 && demand[v] > 0;
  }
  // True if both ends, in map-voxel coordinates, lie in the map (its faces included); a NaN
  // coordinate does not.
  bool holds(const Vec3& a_voxel, const Vec3& b_voxel) const {
    for (int ax = 0; ax < 3; ++ax)
      if (!(a_voxel[ax] >= 0 && b_voxel[ax] >= 0 && a_voxel[ax] <= dims[ax] && b_voxel[ax] <= dims[ax])) return false;
    return true;
  }
  // True if the straight segment a–b (mm) stays inside the map and crosses no zero-demand voxel.
  bool segmentClear(const Vec3& a_mm, const Vec3& b_mm) const;
  const std::vector<double>& supplyAt(std::int64_t voxel) const { return supply_sets[supply_index[voxel]]; }
};

}  // namespace angiosynth
