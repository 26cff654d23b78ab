// Rasterization speed: the N = 1000 VascuSynth-like tree into VascuSynth's 101^3 grid with every
// channel, and a 10k-terminal tree into 512^3 at S = 4 (field of view = the 100^3 map, 40 mm).
#include <benchmark/benchmark.h>

#include <map>

#include "core/memory.hpp"
#include "grow/vascusynth_grower.hpp"
#include "raster/ground_truth.hpp"

using namespace angiosynth;

namespace {

VascularTree grownTree(std::int64_t n) {
  DemandMap m;
  m.dims = {100, 100, 100};
  m.voxel_mm = 0.4;
  m.demand.assign(std::size_t(100) * 100 * 100, 1.0f);
  for (int axis = 0; axis < 3; ++axis)
    for (int a : {35, 55})
      for (int b : {35, 55})
        for (int k = 0; k < 100; ++k)
          for (int j = a; j < a + 10; ++j)
            for (int i = b; i < b + 10; ++i) {
              int c[3];
              c[axis] = k;
              c[(axis + 1) % 3] = j;
              c[(axis + 2) % 3] = i;
              m.demand[m.flat(c[0], c[1], c[2])] = 0.0f;
            }
  m.supply_index.assign(m.demand.size(), 0);
  m.supply_sets = {{0.65, 0.34, 0.01, 7}};
  GrowthOptions o;
  o.terminals = n;
  o.root_mm = Vec3(0, 20, 20);
  o.min_distance_mm = 0.4;
  o.physics.viscosity = 3.6e-3;
  o.physics.perfusion_pressure = 13300;
  o.physics.terminal_pressure = 8300;
  o.physics.perfusion_flow = 8330;
  GrowthReport r;
  return growVascuSynth(m, o, r);
}

void BM_Rasterize(benchmark::State& state) {
  const auto n = state.range(0);
  const int size = static_cast<int>(state.range(1));
  static std::map<std::int64_t, VascularTree> trees;
  if (!trees.count(n)) trees[n] = grownTree(n);
  const VascularTree& tree = trees[n];
  VolumeGrid g;
  g.dims = {size, size, size};
  const double h = size == 101 ? 0.4 : 40.0 / size;  // VascuSynth: floor(100·0.04/0.04)+1 samples at i·h
  g.spacing_mm = Vec3(h, h, h);
  g.origin_mm = size == 101 ? Vec3(0, 0, 0) : Vec3(h / 2, h / 2, h / 2);
  double volume = 0;
  for (auto _ : state) {
    const auto gt = rasterizeGroundTruth(tree, g, RasterOptions{4});
    volume = 0;
    for (float f : gt.fraction.data) volume += f;
    benchmark::DoNotOptimize(gt.mask.data.data());
  }
  state.counters["voxels"] = double(g.voxelCount());
  state.counters["vessel_volume_mm3"] = volume * h * h * h;
  state.counters["peak_rss_MiB"] = double(peakRssBytes()) / double(1 << 20);
}

}  // namespace

BENCHMARK(BM_Rasterize)->ArgNames({"terminals", "size"})->Args({1000, 101})->Args({10000, 512})->Unit(benchmark::kMillisecond)->MinTime(0.5);
BENCHMARK_MAIN();
