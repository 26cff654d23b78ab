// Depth maps of mask domains: exact Euclidean distances (Felzenszwalb & Huttenlocher), in parallel.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "domain/growth_domain.hpp"

namespace angiosynth {

namespace {

// Squared distances along one line to the nearest site (f = 0 at sites, kFar elsewhere):
// Felzenszwalb & Huttenlocher's lower envelope of parabolas, O(n).
constexpr double kFar = 1e20;
void edt1d(const std::vector<double>& f, std::vector<double>& d, std::vector<int>& v, std::vector<double>& z) {
  const int n = int(f.size());
  v.assign(n, 0);
  z.assign(n + 1, 0);
  int k = 0;
  z[0] = -kFar;
  z[1] = kFar;
  for (int q = 1; q < n; ++q) {
    double s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * (q - v[k]));
    while (s <= z[k]) {
      --k;
      s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * (q - v[k]));
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kFar;
  }
  d.resize(n);
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    d[q] = double(q - v[k]) * (q - v[k]) + f[v[k]];
  }
}

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
    for (std::size_t v = 0; v < g.size(); ++v) g[v] = (inside[v] != 0) != to_outside ? 0.0 : kFar;
    for (int axis = 0; axis < (flat ? 2 : 3); ++axis) {
      // The lines along `axis`, indexed by their two other coordinates.
      const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;
      const int len = n[axis], na = n[a];
      const std::size_t lines = std::size_t(n[a]) * n[b];
      const std::size_t stride[3] = {1, std::size_t(n[0]), std::size_t(n[0]) * n[1]};
      const std::size_t step = stride[axis], sa = stride[a], sb = stride[b];
      double* data = g.data();
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lines), [data, len, na, step, sa, sb](const tbb::blocked_range<std::size_t>& r) {
        std::vector<double> f(static_cast<std::size_t>(len)), d, z;
        std::vector<int> v;
        for (std::size_t line = r.begin(); line != r.end(); ++line) {
          double* p = data + (line % std::size_t(na)) * sa + (line / std::size_t(na)) * sb;
          for (int q = 0; q < len; ++q) f[std::size_t(q)] = p[std::size_t(q) * step];
          edt1d(f, d, v, z);
          for (int q = 0; q < len; ++q) p[std::size_t(q) * step] = d[std::size_t(q)];
        }
      });
    }
    for (int k = 0; k < m.dims[2]; ++k)
      for (int j = 0; j < m.dims[1]; ++j)
        for (int i = 0; i < m.dims[0]; ++i) {
          const auto v = at(i + 1, j + 1, k + off);
          if ((inside[v] != 0) == to_outside)
            depth[m.flat(i, j, k)] = float((to_outside ? 1.0 : -1.0) * (std::sqrt(g[v]) - 0.5) * m.voxel_mm);
        }
  }
  return depth;
}

}  // namespace

std::vector<float> maskDepthMap(const DemandMap& m) { return exactDepth(m); }

}  // namespace angiosynth
