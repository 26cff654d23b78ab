#pragma once
// Voxel boxes around parts of the tree, for effects that act near vessels (dropouts, shadows).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "raster/volume.hpp"

namespace angiosynth {

struct VoxelBox {
  std::array<std::int64_t, 3> lo{0, 0, 0}, hi{-1, -1, -1};  // inclusive
};

// Voxels whose centres may lie within `margin` mm of the segment a–b, clipped to the grid.
inline VoxelBox boxAround(const VolumeGrid& g, const Vec3& a, const Vec3& b, double margin) {
  VoxelBox box;
  for (int ax = 0; ax < 3; ++ax) {
    const double lo = (std::min(a[ax], b[ax]) - margin - g.origin_mm[ax]) / g.spacing_mm[ax];
    const double hi = (std::max(a[ax], b[ax]) + margin - g.origin_mm[ax]) / g.spacing_mm[ax];
    box.lo[ax] = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(lo)));
    box.hi[ax] = std::min<std::int64_t>(g.dims[ax] - 1, static_cast<std::int64_t>(std::floor(hi)));
  }
  return box;
}

template <class F>
void forEachInBox(const VoxelBox& b, F&& f) {
  for (std::int64_t k = b.lo[2]; k <= b.hi[2]; ++k)
    for (std::int64_t j = b.lo[1]; j <= b.hi[1]; ++j)
      for (std::int64_t i = b.lo[0]; i <= b.hi[0]; ++i) f(i, j, k);
}

}  // namespace angiosynth
