#pragma once
// Helpers shared by the tests: VascuSynth's example domain and grown trees.
#include <filesystem>
#include <string>

#include "domain/demand_map.hpp"
#include "grow/vascusynth_grower.hpp"
#include "io/map_files.hpp"
#include "io/scenario.hpp"

namespace angiosynth::test {

inline std::filesystem::path sourceDir() { return ANGIOSYNTH_SOURCE_DIR; }

// VascuSynth's 100^3 twelve-rods example from examples/, with N terminals and a seed.
struct Example {
  Scenario scenario;
  DemandMap map;
  GrowthOptions options;
};

inline Example vascusynthExample(std::int64_t terminals, std::uint64_t seed) {
  Example e;
  e.scenario = readParameters(sourceDir() / "examples/vascusynth/param_rods_1000.txt");
  e.map = loadDomain(e.scenario, 4ULL << 30);
  e.options = e.scenario.growth;
  e.options.terminals = terminals;
  e.options.physics.total_terminals = terminals;
  e.options.root_mm = e.map.toMm(e.scenario.root_voxel);
  e.options.seed = seed;
  return e;
}

inline VascularTree grow(const Example& e, GrowthReport* report = nullptr) {
  GrowthReport r;
  auto t = growVascuSynth(e.map, e.options, report ? *report : r);
  return t;
}

}  // namespace angiosynth::test
