// Growth time and peak memory of the VascuSynth grower at 1k, 10k and 100k terminals, with and
// without the no-stub rule; the depth map of a mask domain (an exact distance transform), which
// every mask domain and every part of a tree grown in parts computes first.
// 1k and 10k grow in VascuSynth's 100^3 example map (twelve zero-demand rods); 1k, 10k and 100k
// in a uniform 200^3 map, the series that shows how time per terminal scales with N.
// Parameters as in examples/vascusynth_like (CGS values converted).
// Run bench/run_growth.sh for a table with one process per size (peak RSS is per process).
#include <benchmark/benchmark.h>

#include "bench_common.hpp"
#include "core/memory.hpp"
#include "domain/growth_domain.hpp"
#include "grow/vascusynth/grower.hpp"

using namespace angiosynth;

namespace {

// range(0): terminals; range(1): 0 = VascuSynth's 100^3 rods map, 1 = uniform 200^3; range(2): 1 =
// without the no-stub rule and the final relaxation (min_length_ratio = 0, relax_sweeps = 0: the
// growth as it was before segments shorter than 2r were refused).
void BM_GrowVascuSynth(benchmark::State& state) {
  const auto n = state.range(0);
  const DemandMap map = state.range(1) ? bench::vascusynthMap(200, false) : bench::vascusynthMap(100, true);
  GrowthOptions o = bench::vascusynthOptions(map, n);
  if (state.range(2)) {
    o.min_length_ratio = 0;
    o.relax_sweeps = 0;
  }
  GrowthReport report;
  for (auto _ : state) {
    report = GrowthReport{};
    auto tree = growVascuSynth(map, o, report);
    benchmark::DoNotOptimize(tree.nodeCount());
  }
  state.counters["terminals"] = double(n);
  state.counters["map"] = double(state.range(1));
  state.counters["stubs_allowed"] = double(state.range(2));
  state.counters["us_per_terminal"] = benchmark::Counter(double(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["peak_rss_MiB"] = double(peakRssBytes()) / double(1 << 20);
  state.counters["intersecting_pairs"] = double(report.intersecting_pairs);
  state.counters["repaired"] = double(report.repaired_terminals);
}

// range(0): edge of a cubic map holding a ball of half its width (the inside and the outside
// both get distances).
void BM_MaskDepth(benchmark::State& state) {
  const int n = int(state.range(0));
  DemandMap map;
  map.dims = {n, n, n};
  map.demand.assign(std::size_t(n) * n * n, 0.0f);
  const double c = 0.5 * (n - 1), r = 0.25 * n;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        if ((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c) <= r * r) map.demand[std::size_t(map.flat(i, j, k))] = 1.0f;
  for (auto _ : state) benchmark::DoNotOptimize(maskDepthMap(map).data());
  state.counters["Mvoxels_per_s"] = benchmark::Counter(double(map.voxelCount()) * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

BENCHMARK(BM_MaskDepth)->ArgName("edge")->Arg(128)->Arg(320)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_GrowVascuSynth)
    ->ArgNames({"terminals", "uniform200", "stubs"})
    ->ArgsProduct({{1000, 10000}, {0}, {0, 1}})
    ->ArgsProduct({{1000, 10000, 100000}, {1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_MAIN();
