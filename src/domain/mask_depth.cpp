// The only translation unit of the domain module that includes OpenVDB.
#include <openvdb/openvdb.h>
#include <openvdb/tools/FastSweeping.h>

#include <mutex>

#include "domain/growth_domain.hpp"

namespace angiosynth {

std::vector<float> maskDepthMap(const DemandMap& m) {
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
