#pragma once
// The domains and growth parameters the benchmarks share: VascuSynth's example (100³ map of
// 0.4 mm voxels, optionally with its twelve zero-demand rods, or a uniform map of n³), with
// its CGS parameters converted (13300/8300 Pa, 8330 mm³/s, 3.6 mPa·s).
#include "domain/demand_map.hpp"
#include "grow/vascusynth/grower.hpp"

namespace angiosynth::bench {

inline DemandMap vascusynthMap(int n, bool rods) {
  DemandMap m;
  m.dims = {n, n, n};
  m.voxel_mm = 0.4;
  m.demand.assign(std::size_t(n) * n * n, 1.0f);
  if (rods) {
    const int s = n / 100;
    for (int axis = 0; axis < 3; ++axis)
      for (int a : {35, 55})
        for (int b : {35, 55})
          for (int k = 0; k < n; ++k)
            for (int j = a * s; j < (a + 10) * s; ++j)
              for (int i = b * s; i < (b + 10) * s; ++i) {
                int c[3];
                c[axis] = k;
                c[(axis + 1) % 3] = j;
                c[(axis + 2) % 3] = i;
                m.demand[m.flat(c[0], c[1], c[2])] = 0.0f;
              }
  }
  m.supply_index.assign(m.demand.size(), 0);
  m.supply_sets = {{0.65, 0.34, 0.01, 7}};
  return m;
}

// Root at the middle of the map's x = 0 face, as in VascuSynth's example (0, 50, 50).
inline GrowthOptions vascusynthOptions(const DemandMap& map, std::int64_t terminals) {
  GrowthOptions o;
  o.terminals = terminals;
  o.root_mm = Vec3(0, map.dims[1] / 2.0, map.dims[2] / 2.0) * map.voxel_mm;
  o.min_distance_mm = map.voxel_mm;
  o.closest_neighbours = 5;
  o.physics.viscosity = 3.6e-3;
  o.physics.perfusion_pressure = 13300;
  o.physics.terminal_pressure = 8300;
  o.physics.perfusion_flow = 8330;
  o.seed = 1;
  return o;
}

}  // namespace angiosynth::bench
