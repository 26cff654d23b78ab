// Rasterization speed: the N = 1000 VascuSynth-like tree into VascuSynth's 101^3 grid with every
// channel, and a 10k-terminal tree into 512^3 at S = 4 (field of view = the 100^3 map, 40 mm).
#include <benchmark/benchmark.h>

#include <map>

#include "bench_common.hpp"
#include "core/memory.hpp"
#include "grow/vascusynth/grower.hpp"
#include "raster/ground_truth.hpp"

using namespace angiosynth;

namespace {

VascularTree grownTree(std::int64_t n) {
  const DemandMap m = bench::vascusynthMap(100, true);
  GrowthReport r;
  return growVascuSynth(m, bench::vascusynthOptions(m, n), r);
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
