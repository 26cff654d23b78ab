#pragma once
// A small sample (24 terminals, 16^3 voxels) through the whole pipeline with a fuzzed profile;
// no volume files are written (formats = []), the degradation itself runs in full.
#include "fuzz_support.hpp"
#include "config/scenario.hpp"
#include "pipeline/generate_sample.hpp"

namespace angiosynth::fuzz {

inline void degradeSmallSample(const Profile& profile) {
  static const Scenario sc = [] {
    const auto map = scratchDir() / "map16.txt";
    std::ofstream(map) << "16 16 16\n0 0 0 16 16 16\n1\n";
    const auto params = scratchDir() / "small.toml";
    std::ofstream(params) << "seed = 3\n[domain]\ndemand_map = \"" << map.string()
                          << "\"\nvoxel_size = \"1 mm\"\n[tree]\nterminals = 24\nroot_voxel = [0, 8, 8]\n"
                             "[physics]\nviscosity = \"3.6 mPa*s\"\nperfusion_pressure = \"13300 Pa\"\n"
                             "terminal_pressure = \"8300 Pa\"\nperfusion_flow = \"100 mm3/s\"\n"
                             "[image]\nformats = []\ngraph_formats = []\n";
    return readTomlParameters(params);
  }();
  const auto out = scratchDir() / "out";
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);
  SampleRequest req;
  req.scenario = &sc;
  req.memory_limit = kMemoryLimit;
  req.profiles = std::vector<Profile>{profile};
  generateSample(req, out);
}

// A parameter file grown into a fresh `out` (its graphs only, no image), as `generate
// --no-image` writes it.
inline void growParameterFile(const std::filesystem::path& params, const std::filesystem::path& out) {
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);
  Scenario sc = readTomlParameters(params);
  sc.image.enabled = false;
  SampleRequest req;
  req.scenario = &sc;
  req.memory_limit = kMemoryLimit;
  generateSample(req, out);
}

}  // namespace angiosynth::fuzz
