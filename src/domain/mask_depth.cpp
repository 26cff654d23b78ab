// Depth maps of mask domains: exact Euclidean distances (Felzenszwalb & Huttenlocher), in parallel.
#include <cmath>

#include "core/distance_transform.hpp"
#include "domain/growth_domain.hpp"

namespace angiosynth {

namespace {

// Depth of a map, exact: the distance from each voxel centre to the nearest centre of the other
// side, minus half a voxel (the border lies halfway), signed; separable squared distances
// (x, y, then z lines), each line independent. One-slice maps are 2D (no z pass: a slab of
// slices would bound the depth by its thickness).
std::vector<float> exactDepth(const DemandMap& m) {
  const bool flat = m.dims[2] == 1;
  // One layer of outside voxels around the map (none along z for one-slice maps).
  const int n[3] = {m.dims[0] + 2, m.dims[1] + 2, flat ? 1 : m.dims[2] + 2};
  const int off = flat ? 0 : 1;
  const auto at = [&](int i, int j, int k) { return (std::size_t(k) * n[1] + j) * n[0] + i; };
  std::vector<char> inside(std::size_t(n[0]) * n[1] * n[2], 0);
  for (int k = 0; k < m.dims[2]; ++k)
    for (int j = 0; j < m.dims[1]; ++j)
      for (int i = 0; i < m.dims[0]; ++i) inside[at(i + 1, j + 1, k + off)] = m.demand[m.flat(i, j, k)] > 0;
  std::vector<float> depth(m.voxelCount());
  std::vector<double> g(inside.size());
  for (const bool to_outside : {true, false}) {
    for (std::size_t v = 0; v < g.size(); ++v) g[v] = (inside[v] != 0) != to_outside ? 0.0 : kFarSquared;
    squaredDistances(g, {n[0], n[1], n[2]}, {1.0, 1.0, 1.0}, flat ? 2 : 3);
    for (int k = 0; k < m.dims[2]; ++k)
      for (int j = 0; j < m.dims[1]; ++j)
        for (int i = 0; i < m.dims[0]; ++i) {
          const auto v = at(i + 1, j + 1, k + off);
          if ((inside[v] != 0) == to_outside) depth[m.flat(i, j, k)] = float((to_outside ? 1.0 : -1.0) * (std::sqrt(g[v]) - 0.5) * m.voxel_mm);
        }
  }
  return depth;
}

}  // namespace

std::vector<float> maskDepthMap(const DemandMap& m) { return exactDepth(m); }

}  // namespace angiosynth
