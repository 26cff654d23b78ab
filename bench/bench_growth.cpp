// Growth time and peak memory of the VascuSynth grower at 1k, 10k and 100k terminals.
// 1k and 10k grow in VascuSynth's 100^3 example map (twelve zero-demand rods); 1k, 10k and 100k
// in a uniform 200^3 map, the series that shows how time per terminal scales with N.
// Parameters as in examples/vascusynth_like (CGS values converted).
// Run bench/run_growth.sh for a table with one process per size (peak RSS is per process).
#include <benchmark/benchmark.h>

#include "core/memory.hpp"
#include "grow/vascusynth_grower.hpp"

using namespace angiosynth;

namespace {

DemandMap makeMap(int n, bool rods) {
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

// range(0): terminals; range(1): 0 = VascuSynth's 100^3 rods map, 1 = uniform 200^3.
void BM_GrowVascuSynth(benchmark::State& state) {
  const auto n = state.range(0);
  const DemandMap map = state.range(1) ? makeMap(200, false) : makeMap(100, true);
  GrowthOptions o;
  o.terminals = n;
  o.root_mm = Vec3(0, 50, 50) * (map.dims[0] / 100) * map.voxel_mm;
  o.min_distance_mm = map.voxel_mm;
  o.closest_neighbours = 5;
  o.physics.viscosity = 3.6e-3;
  o.physics.perfusion_pressure = 13300;
  o.physics.terminal_pressure = 8300;
  o.physics.perfusion_flow = 8330;
  o.seed = 1;
  GrowthReport report;
  for (auto _ : state) {
    report = GrowthReport{};
    auto tree = growVascuSynth(map, o, report);
    benchmark::DoNotOptimize(tree.nodeCount());
  }
  state.counters["terminals"] = double(n);
  state.counters["map"] = double(state.range(1));
  state.counters["us_per_terminal"] =
      benchmark::Counter(double(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["peak_rss_MiB"] = double(peakRssBytes()) / double(1 << 20);
  state.counters["intersecting_pairs"] = double(report.intersecting_pairs);
  state.counters["repaired"] = double(report.repaired_terminals);
}

}  // namespace

BENCHMARK(BM_GrowVascuSynth)
    ->ArgNames({"terminals", "uniform200"})
    ->Args({1000, 0})
    ->Args({10000, 0})
    ->Args({1000, 1})
    ->Args({10000, 1})
    ->Args({100000, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_MAIN();
