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

// The box of voxels a terminal's supply may reach: c its voxel's supply coefficients (the last is
// the cut-off), t its position in map voxels. Empty (c null) where the terminal supplies nothing.
struct SupplyReach {
  const std::vector<double>* c = nullptr;
  Vec3 t;
  int lo[3] = {0, 0, 0}, hi[3] = {-1, -1, -1};
};

SupplyReach supplyReach(const DemandMap& map, const Vec3& terminal_mm) {
  SupplyReach r;
  const auto home = map.voxelAt(terminal_mm);
  if (home < 0 || map.supplyAt(home).empty()) return r;
  r.c = &map.supplyAt(home);
  const double cutoff = r.c->back();
  r.t = map.toVoxel(terminal_mm);
  for (int ax = 0; ax < 3; ++ax) {
    r.lo[ax] = std::max(0, static_cast<int>(std::floor(r.t[ax] - cutoff - 0.5)));
    r.hi[ax] = std::min(map.dims[ax] - 1, static_cast<int>(std::ceil(r.t[ax] + cutoff - 0.5)));
  }
  return r;
}

// Calls supply(i, j, k, c, d) for every voxel (i, j, k) in slices [k_first, k_last] within the
// cut-off of the terminal, in index order: c the supply coefficients of the terminal's voxel, d
// the distance in map voxels.
template <class Supply>
void forEachSuppliedVoxel(const DemandMap& map, const SupplyReach& r, int k_first, int k_last, Supply&& supply) {
  if (!r.c) return;
  const auto& c = *r.c;
  const double cutoff = c.back();
  for (int k = std::max(r.lo[2], k_first); k <= std::min(r.hi[2], k_last); ++k)
    for (int j = r.lo[1]; j <= r.hi[1]; ++j)
      for (int i = r.lo[0]; i <= r.hi[0]; ++i) {
        const double d = distance(r.t, Vec3(i + 0.5, j + 0.5, k + 0.5));
        if (d >= cutoff) continue;
        supply(i, j, k, c, d);
      }
}

}  // namespace

void perfuse(const DemandMap& map, DemandSampler& sampler, const Vec3& terminal_mm, std::vector<std::pair<std::int64_t, double>>& scratch) {
  scratch.clear();
  forEachSuppliedVoxel(map, supplyReach(map, terminal_mm), 0, map.dims[2] - 1, [&](int i, int j, int k, const std::vector<double>& c, double d) {
    const auto v = map.flat(i, j, k);
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
        forEachSuppliedVoxel(map, supplyReach(map, t), slabs.begin(), slabs.end() - 1,
                             [&](int i, int j, int k, const std::vector<double>& c, double d) {
                               double& x = demand[std::size_t(map.flat(i, j, k))];
                               if (x > 0) x = x * supplyFactor(c, d);
                             });
    });
  });
}

void reperfuse(const DemandMap& map, DemandSampler& sampler, const std::vector<Vec3>& changed_mm, const std::vector<Vec3>& terminals_mm) {
  // The voxels to recompute live in blocks of 8³ voxels, each given a slot of values when it
  // holds one: a terminal whose reach meets no such block is passed over without visiting its
  // voxels, and a voxel finds its value without a search.
  constexpr int kShift = 3, kBlock = 1 << kShift, kMask = kBlock - 1;
  int blocks[3];
  for (int ax = 0; ax < 3; ++ax) blocks[ax] = (map.dims[ax] + kMask) >> kShift;
  const auto blockOf = [&](int bi, int bj, int bk) {
    return (std::size_t(bk) * std::size_t(blocks[1]) + std::size_t(bj)) * std::size_t(blocks[0]) + std::size_t(bi);
  };
  const auto within = [](int i, int j, int k) { return std::size_t((((k & kMask) << kShift | (j & kMask)) << kShift) | (i & kMask)); };
  std::vector<std::int32_t> slot(std::size_t(blocks[0]) * std::size_t(blocks[1]) * std::size_t(blocks[2]), -1);
  std::vector<char> wanted;
  std::vector<double> value;
  std::vector<std::pair<std::int64_t, std::size_t>> voxels;  // (voxel, its value's index)
  for (const Vec3& t : changed_mm)
    forEachSuppliedVoxel(map, supplyReach(map, t), 0, map.dims[2] - 1, [&](int i, int j, int k, const auto&, double) {
      auto& b = slot[blockOf(i >> kShift, j >> kShift, k >> kShift)];
      if (b < 0) {
        b = static_cast<std::int32_t>(wanted.size() >> (3 * kShift));
        wanted.resize(wanted.size() + (std::size_t(1) << (3 * kShift)), 0);
        value.resize(wanted.size(), 0.0);
      }
      const std::size_t at = (std::size_t(b) << (3 * kShift)) | within(i, j, k);
      if (wanted[at]) return;
      wanted[at] = 1;
      const auto v = map.flat(i, j, k);
      value[at] = DemandSampler::weightOf(map.demand[std::size_t(v)]);
      voxels.emplace_back(v, at);
    });
  if (voxels.empty()) return;
  std::vector<SupplyReach> touching;
  for (const Vec3& t : terminals_mm) {
    const SupplyReach r = supplyReach(map, t);
    if (!r.c) continue;
    bool touches = false;
    for (int bk = r.lo[2] >> kShift; bk <= r.hi[2] >> kShift && !touches; ++bk)
      for (int bj = r.lo[1] >> kShift; bj <= r.hi[1] >> kShift && !touches; ++bj)
        for (int bi = r.lo[0] >> kShift; bi <= r.hi[0] >> kShift && !touches; ++bi) touches = slot[blockOf(bi, bj, bk)] >= 0;
    if (touches) touching.push_back(r);
  }
  // As in perfusedDemand: a slab's voxels see the terminals in order, whichever thread takes it.
  tbb::parallel_for(tbb::blocked_range<int>(0, map.dims[2], 4), [&](const tbb::blocked_range<int>& slabs) {
    for (const SupplyReach& r : touching)
      forEachSuppliedVoxel(map, r, slabs.begin(), slabs.end() - 1, [&](int i, int j, int k, const std::vector<double>& c, double d) {
        const auto b = slot[blockOf(i >> kShift, j >> kShift, k >> kShift)];
        if (b < 0) return;
        const std::size_t at = (std::size_t(b) << (3 * kShift)) | within(i, j, k);
        if (!wanted[at]) return;
        double& x = value[at];
        if (x > 0) x = x * supplyFactor(c, d);
      });
  });
  std::sort(voxels.begin(), voxels.end());
  std::vector<std::pair<std::int64_t, double>> updates;
  updates.reserve(voxels.size());
  for (const auto& [v, at] : voxels) updates.emplace_back(v, value[at]);
  sampler.update(updates);
}

}  // namespace angiosynth
