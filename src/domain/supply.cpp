#include "domain/supply.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace angiosynth {

double supplyFactor(const std::vector<double>& c, double d) {
  if (c.empty() || d >= c.back()) return 1.0;
  if (d <= 0) return 0.0;
  double sum = 0, dp = 1;
  for (double ci : c) {
    sum += ci * dp;
    dp *= d;
  }
  return sum > 0 ? std::max(0.0, 1.0 - 1.0 / sum) : 0.0;
}

namespace {

// Calls supply(v, c, d) for every voxel v in slices [k_first, k_last] within the cut-off of the
// terminal (mm), in index order: c the supply coefficients of the terminal's voxel, d the
// distance in map voxels.
template <class Supply>
void forEachSuppliedVoxel(const DemandMap& map, const Vec3& terminal_mm, int k_first, int k_last, Supply&& supply) {
  const auto home = map.voxelAt(terminal_mm);
  if (home < 0) return;
  const auto& c = map.supplyAt(home);
  if (c.empty()) return;
  const double cutoff = c.back();
  const Vec3 t = map.toVoxel(terminal_mm);
  int lo[3], hi[3];
  for (int ax = 0; ax < 3; ++ax) {
    lo[ax] = std::max(0, static_cast<int>(std::floor(t[ax] - cutoff - 0.5)));
    hi[ax] = std::min(map.dims[ax] - 1, static_cast<int>(std::ceil(t[ax] + cutoff - 0.5)));
  }
  for (int k = std::max(lo[2], k_first); k <= std::min(hi[2], k_last); ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const double d = distance(t, Vec3(i + 0.5, j + 0.5, k + 0.5));
        if (d >= cutoff) continue;
        supply(map.flat(i, j, k), c, d);
      }
}

}  // namespace

void perfuse(const DemandMap& map, DemandSampler& sampler, const Vec3& terminal_mm, std::vector<std::pair<std::int64_t, double>>& scratch) {
  scratch.clear();
  forEachSuppliedVoxel(map, terminal_mm, 0, map.dims[2] - 1, [&](std::int64_t v, const std::vector<double>& c, double d) {
    const double old = sampler.value(v);
    if (old > 0) scratch.emplace_back(v, old * supplyFactor(c, d));
  });
  sampler.update(scratch);
}

DemandSampler perfusedDemand(const DemandMap& map, const std::vector<Vec3>& terminals_mm) {
  return DemandSampler(map.demand, [&](std::span<double> demand) {
    // A slab's voxels see the terminals in the given order, whichever thread takes the slab.
    tbb::parallel_for(tbb::blocked_range<int>(0, map.dims[2], 4), [&](const tbb::blocked_range<int>& slabs) {
      for (const Vec3& t : terminals_mm)
        forEachSuppliedVoxel(map, t, slabs.begin(), slabs.end() - 1, [&](std::int64_t v, const std::vector<double>& c, double d) {
          double& x = demand[std::size_t(v)];
          if (x > 0) x = x * supplyFactor(c, d);
        });
    });
  });
}

}  // namespace angiosynth
