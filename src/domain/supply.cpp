#include "domain/supply.hpp"

#include <algorithm>
#include <cmath>

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

void perfuse(const DemandMap& map, DemandSampler& sampler, const Vec3& terminal_mm, std::vector<std::pair<std::int64_t, double>>& scratch) {
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
  scratch.clear();
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const double d = distance(t, Vec3(i + 0.5, j + 0.5, k + 0.5));
        if (d >= cutoff) continue;
        const auto v = map.flat(i, j, k);
        const double old = sampler.value(v);
        if (old <= 0) continue;
        scratch.emplace_back(v, old * supplyFactor(c, d));
      }
  sampler.update(scratch);
}

}  // namespace angiosynth
