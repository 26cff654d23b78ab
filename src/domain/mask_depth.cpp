// The only translation unit of the domain module that includes OpenVDB.
#include <openvdb/openvdb.h>
#include <openvdb/tools/FastSweeping.h>

#include <cmath>
#include <mutex>

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

// Depth of a one-slice map, exact in 2D: the distance from each voxel centre to the nearest
// centre of the other side, minus half a voxel (the border lies halfway), signed.
std::vector<float> flatDepth(const DemandMap& m) {
  const int nx = m.dims[0] + 2, ny = m.dims[1] + 2;  // with one layer of outside voxels around
  const auto inside = [&](int i, int j) {
    return i >= 1 && j >= 1 && i <= m.dims[0] && j <= m.dims[1] && m.demand[m.flat(i - 1, j - 1, 0)] > 0;
  };
  std::vector<float> depth(m.voxelCount());
  std::vector<double> f, d, z, col(std::size_t(nx) * ny);
  std::vector<int> v;
  for (const bool to_outside : {true, false}) {
    // Squared distance (voxels²) to the nearest voxel of the other side: columns, then rows.
    for (int i = 0; i < nx; ++i) {
      f.assign(ny, kFar);
      for (int j = 0; j < ny; ++j)
        if (inside(i, j) != to_outside) f[j] = 0;
      edt1d(f, d, v, z);
      for (int j = 0; j < ny; ++j) col[std::size_t(j) * nx + i] = d[j];
    }
    for (int j = 0; j < ny; ++j) {
      f.assign(col.begin() + std::ptrdiff_t(j) * nx, col.begin() + std::ptrdiff_t(j + 1) * nx);
      edt1d(f, d, v, z);
      for (int i = 1; i <= m.dims[0]; ++i)
        if (j >= 1 && j <= m.dims[1] && inside(i, j) == to_outside)
          depth[m.flat(i - 1, j - 1, 0)] = float((to_outside ? 1.0 : -1.0) * (std::sqrt(d[i]) - 0.5) * m.voxel_mm);
    }
  }
  return depth;
}

}  // namespace

std::vector<float> maskDepthMap(const DemandMap& m) {
  // One-slice maps: exact 2D distances (a slab of slices would bound the depth by its thickness).
  if (m.dims[2] == 1) return flatDepth(m);
  static std::once_flag init;
  std::call_once(init, [] { openvdb::initialize(); });
  const bool flat = m.dims[2] == 1;
  // Fog: 1 inside, 0 outside, every voxel active, with one layer of outside voxels around the
  // map (none along z for one-slice maps, whose slice is repeated so that z has no border).
  auto fog = openvdb::FloatGrid::create(0.0f);
  fog->setTransform(openvdb::math::Transform::createLinearTransform(m.voxel_mm));
  auto acc = fog->getAccessor();
  const int kz0 = -1, kz1 = flat ? 1 : m.dims[2];
  for (int k = kz0; k <= kz1; ++k)
    for (int j = -1; j <= m.dims[1]; ++j)
      for (int i = -1; i <= m.dims[0]; ++i) {
        const int kk = flat ? 0 : k;
        const bool in = i >= 0 && j >= 0 && kk >= 0 && i < m.dims[0] && j < m.dims[1] && kk < m.dims[2] &&
                        m.demand[m.flat(i, j, kk)] > 0;
        acc.setValueOn(openvdb::Coord(i, j, k), in ? 1.0f : 0.0f);
      }
  auto sdf = openvdb::tools::fogToSdf(*fog, 0.5f, 1);
  auto sacc = sdf->getConstAccessor();
  std::vector<float> depth(m.voxelCount());
  for (int k = 0; k < m.dims[2]; ++k)
    for (int j = 0; j < m.dims[1]; ++j)
      for (int i = 0; i < m.dims[0]; ++i) depth[m.flat(i, j, k)] = -sacc.getValue(openvdb::Coord(i, j, k));
  return depth;
}

}  // namespace angiosynth
