#pragma once
// Voxel boxes around parts of the tree, for effects that act near vessels (dropouts, shadows).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include <vector>

#include "core/vascular_tree.hpp"
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

// A segment drawn with probability ∝ its length among those `eligible` takes (all by default),
// and a uniform position along it.
struct PlaceOnTree {
  std::vector<double> cumulative;  // by node id: the eligible length up to and including segment s
  template <class Eligible>
  PlaceOnTree(const VascularTree& t, Eligible&& eligible) {
    cumulative.assign(std::max(t.nodeCount(), 1), 0.0);
    for (std::int32_t s = 1; s < t.nodeCount(); ++s) cumulative[s] = cumulative[s - 1] + (eligible(s) ? t.length[s] : 0.0);
  }
  explicit PlaceOnTree(const VascularTree& t) : PlaceOnTree(t, [](std::int32_t) { return true; }) {}
  double total() const { return cumulative.back(); }
  // u uniform in [0, 1); `along` the distance from the segment's proximal node.
  std::int32_t draw(double u, double& along) const {
    const double x = u * cumulative.back();
    auto it = std::upper_bound(cumulative.begin() + 1, cumulative.end(), x);
    auto s = static_cast<std::int32_t>(std::min<std::ptrdiff_t>(it - cumulative.begin(), cumulative.size() - 1));
    while (s > 1 && cumulative[s] == cumulative[s - 1]) --s;  // x at the very end: the last segment with length
    along = std::clamp(x - cumulative[s - 1], 0.0, cumulative[s] - cumulative[s - 1]);
    return s;
  }
  std::int32_t draw(double u) const {
    double along;
    return draw(u, along);
  }
};

template <class F>
void forEachInBox(const VoxelBox& b, F&& f) {
  for (std::int64_t k = b.lo[2]; k <= b.hi[2]; ++k)
    for (std::int64_t j = b.lo[1]; j <= b.hi[1]; ++j)
      for (std::int64_t i = b.lo[0]; i <= b.hi[0]; ++i) f(i, j, k);
}

}  // namespace angiosynth
