// Degradation speed: one Gaussian noise pass on VascuSynth's 101³ grid, and the whole `cta`
// profile (texture, anisotropic blur, Gaussian noise) on 256³, both on the N = 1000 example tree.
// Also the domain-randomisation profile with every effect applied (warp included) on 256³, and
// each effect alone (its defaults, a value of its kind for what it requires) on 128³ and 256³.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "bench_common.hpp"
#include "core/memory.hpp"
#include "degrade/degrade.hpp"
#include "grow/vascusynth/grower.hpp"

using namespace angiosynth;

namespace {

struct Scene {
  VascularTree tree;
  GroundTruthVolumes truth;
};

const Scene& scene(int size) {
  static std::map<int, Scene> scenes;
  if (!scenes.count(size)) {
    const DemandMap m = bench::vascusynthMap(100, true);
    GrowthReport r;
    Scene s;
    s.tree = growVascuSynth(m, bench::vascusynthOptions(m, 1000), r);
    VolumeGrid g;
    g.dims = {size, size, size};
    const double h = 40.0 / size;
    g.spacing_mm = Vec3(h, h, h);
    g.origin_mm = Vec3(h / 2, h / 2, h / 2);
    s.truth = rasterizeGroundTruth(s.tree, g, RasterOptions{4});
    scenes[size] = std::move(s);
  }
  return scenes[size];
}

Profile shipped(const std::string& name) { return readProfileToml(std::string(ANGIOSYNTH_SOURCE_DIR) + "/noise_profiles/" + name + ".toml"); }

void runProfile(benchmark::State& state, const Profile& p, int size) {
  const Scene& s = scene(size);
  DegradeInput in;
  in.tree = &s.tree;
  in.truth = &s.truth;
  std::uint64_t seed = 1;
  nlohmann::ordered_json seconds;
  for (auto _ : state) {
    in.seed = seed++;
    const auto d = degradeImage(p, in);
    benchmark::DoNotOptimize(d.image.data.data());
    seconds = d.seconds;
  }
  for (const auto& [k, v] : seconds.items()) state.counters[k] = v.get<double>();
  state.counters["voxels"] = double(s.truth.fraction.grid.voxelCount());
  state.counters["peak_rss_MiB"] = double(peakRssBytes()) / double(1 << 20);
}

// The Gaussian pass alone, applied straight to a state (no profile set-up, no image fill).
void BM_GaussianPass101(benchmark::State& state) {
  const Scene& s = scene(101);
  DegradeState st;
  st.grid = s.truth.fraction.grid;
  st.image = Volume<float>(st.grid);
  st.fraction = &s.truth.fraction;
  st.tree = &s.tree;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    Rng rng(seed++, 0, Stage::Degrade, 1);
    nlohmann::ordered_json rec;
    EffectContext ctx{st, rng, rec, "", 0};
    Drawn d;
    d.values["mean"] = Vec3();
    d.values["sigma"] = Vec3(20, 20, 20);
    findEffectType("gaussian")->apply(d, ctx);
    benchmark::DoNotOptimize(st.image.data.data());
  }
  state.counters["voxels"] = double(st.grid.voxelCount());
  state.counters["ns_per_voxel"] =
      benchmark::Counter(double(st.grid.voxelCount()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_CtaProfile256(benchmark::State& state) { runProfile(state, shipped("cta"), 256); }

void BM_DomainRandomisationAllEffects256(benchmark::State& state) {
  Profile p = shipped("domain_randomisation");
  for (auto& e : p.effects) e.probability.reset();
  runProfile(state, p, 256);
}

// One effect alone: a profile of it and nothing else, read from a file as users write them.
Profile oneEffect(const EffectType& t) {
  const auto path = std::filesystem::temp_directory_path() / ("angiosynth_bench_" + std::to_string(::getpid()) + "_" + t.name + ".toml");
  std::ofstream(path) << "background = 40\nvessel = 300\ndtype = \"float32\"\n" << exampleEffectToml(t);
  Profile p = readProfileToml(path);
  std::filesystem::remove(path);
  return p;
}

const bool kEachEffect = [] {
  for (const EffectType* t : effectTypes())
    for (int size : {128, 256})
      benchmark::RegisterBenchmark(("BM_Effect/" + std::string(t->name) + "/" + std::to_string(size)).c_str(),
                                   [t, size](benchmark::State& state) { runProfile(state, oneEffect(*t), size); })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.5);
  return true;
}();

}  // namespace

BENCHMARK(BM_GaussianPass101)->Unit(benchmark::kMillisecond)->MinTime(0.5);
BENCHMARK(BM_CtaProfile256)->Unit(benchmark::kMillisecond)->MinTime(2);
BENCHMARK(BM_DomainRandomisationAllEffects256)->Unit(benchmark::kMillisecond)->MinTime(2);
BENCHMARK_MAIN();
