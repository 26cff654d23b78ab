// Growth time and peak memory of the VascuSynth grower at 1k, 10k and 100k terminals, with and
// without the no-stub rule.
// 1k and 10k grow in VascuSynth's 100^3 example map (twelve zero-demand rods); 1k, 10k and 100k
// in a uniform 200^3 map, the series that shows how time per terminal scales with N.
// Parameters as in examples/vascusynth_like (CGS values converted).
// Run bench/run_growth.sh for a table with one process per size (peak RSS is per process).
#include <benchmark/benchmark.h>

#include "bench_common.hpp"
#include "core/memory.hpp"
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

}  // namespace

BENCHMARK(BM_GrowVascuSynth)
    ->ArgNames({"terminals", "uniform200", "stubs"})
    ->ArgsProduct({{1000, 10000}, {0}, {0, 1}})
    ->ArgsProduct({{1000, 10000, 100000}, {1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK_MAIN();
