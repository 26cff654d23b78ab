#pragma once
// Helpers shared by the tests: VascuSynth's example domain and grown trees.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "domain/demand_map.hpp"
#include "grow/vascusynth/grower.hpp"
#include "grow/vascusynth/setup.hpp"
#include "io/map_files.hpp"
#include "config/scenario.hpp"

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
  const auto& vs = dynamic_cast<const VascuSynthSetup&>(*e.scenario.growth);
  e.map = loadDomain(vs.domain, 4ULL << 30);
  e.options = vs.growth;
  e.options.terminals = terminals;
  e.options.physics.total_terminals = terminals;
  e.options.root_mm = e.map.toMm(vs.domain.root_voxel);
  e.options.seed = seed;
  return e;
}

inline VascularTree grow(const Example& e, GrowthReport* report = nullptr) {
  GrowthReport r;
  auto t = growVascuSynth(e.map, e.options, report ? *report : r);
  return t;
}

// Murray's law, flow conservation, equal terminal flows and pressures, and Poiseuille drops on
// both sides of every bifurcation, each to 1e-9 relative; root flow (terminals × q_term, by
// default Q_perf) at P_perf. A draining tree (a vein) gains pressure towards its terminals.
inline void expectHemodynamicInvariants(const VascularTree& t, const PhysicsParameters& p, std::int64_t terminals, double q_term = 0) {
  ASSERT_EQ(t.terminalCount(), terminals);
  ASSERT_EQ(t.nodeCount(), 2 * terminals);
  if (q_term == 0) q_term = p.perfusion_flow / double(terminals);
  const double drop = std::abs(p.perfusion_pressure - p.terminal_pressure);
  const double sign = p.terminal_pressure > p.perfusion_pressure ? -1 : 1;
  const double k = 8 * p.viscosity / std::numbers::pi;
  std::int64_t bifurcations = 0;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    if (t.isTerminal(i)) {
      EXPECT_NEAR(t.flow[i], q_term, 1e-9 * q_term);
      EXPECT_NEAR(t.pressure[i], p.terminal_pressure, 1e-9 * drop) << "terminal " << i;
      continue;
    }
    ++bifurcations;
    const auto a = t.child0[i], b = t.child1[i];
    EXPECT_NEAR(t.flow[i], t.flow[a] + t.flow[b], 1e-9 * t.flow[i]);
    const double g = MurrayLaw(p).exponentAt(t.radius[i]);  // γ, or the band's of the parent radius
    const double lhs = std::pow(t.radius[i], g), rhs = std::pow(t.radius[a], g) + std::pow(t.radius[b], g);
    EXPECT_NEAR(lhs, rhs, 1e-9 * lhs) << "segment " << i;
    for (auto c : {a, b}) {
      const double dp = t.flow[c] * k * t.length[c] / std::pow(t.radius[c], 4);
      EXPECT_NEAR(t.pressure[c], t.pressure[i] - sign * dp, 1e-9 * drop) << "segment " << c;
    }
  }
  EXPECT_EQ(bifurcations, terminals - 1);
  EXPECT_NEAR(t.flow[t.rootSegment()], q_term * double(terminals), 1e-9 * q_term * double(terminals));
  EXPECT_EQ(t.pressure[0], p.perfusion_pressure);
}

}  // namespace angiosynth::test
