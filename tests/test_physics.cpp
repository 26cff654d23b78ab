// Physics invariants on real generated trees (seed 002 §2, §3.7–3.8), each to 1e-9 relative.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "physics/hemodynamics.hpp"
#include "test_support.hpp"

using namespace angiosynth;

namespace {

class GrownTree : public ::testing::TestWithParam<std::uint64_t> {
 protected:
  static void SetUpTestSuite() {}
};

TEST_P(GrownTree, MurrayFlowAndPressureInvariantsHold) {
  auto ex = test::vascusynthExample(400, GetParam());
  const VascularTree t = test::grow(ex);
  const auto& p = ex.options.physics;
  ASSERT_EQ(t.terminalCount(), 400);
  ASSERT_EQ(t.nodeCount(), 2 * 400);
  const double q_term = p.perfusion_flow / 400;
  int bifurcations = 0;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    if (t.isTerminal(i)) {
      // Equal terminal flow and the same root-to-terminal pressure drop P_perf − P_term.
      EXPECT_NEAR(t.flow[i], q_term, 1e-9 * q_term);
      EXPECT_NEAR(t.pressure[i], p.terminal_pressure, 1e-9 * (p.perfusion_pressure - p.terminal_pressure));
      continue;
    }
    ++bifurcations;
    const auto a = t.child0[i], b = t.child1[i];
    // Flow conservation at every bifurcation.
    EXPECT_NEAR(t.flow[i], t.flow[a] + t.flow[b], 1e-9 * t.flow[i]);
    // Murray's law r_p^γ = r_a^γ + r_b^γ.
    const double g = p.murray_exponent;
    const double lhs = std::pow(t.radius[i], g), rhs = std::pow(t.radius[a], g) + std::pow(t.radius[b], g);
    EXPECT_NEAR(lhs, rhs, 1e-9 * lhs) << "segment " << i;
    // Poiseuille: both children see the same pressure drop to the terminals, i.e. equal
    // pressures at the bifurcation computed from either side.
    const double k = 8 * p.viscosity / std::numbers::pi;
    const double dp_a = t.flow[a] * k * t.length[a] / std::pow(t.radius[a], 4);
    EXPECT_NEAR(t.pressure[a], t.pressure[i] - dp_a, 1e-9 * (p.perfusion_pressure - p.terminal_pressure));
  }
  EXPECT_EQ(bifurcations, 399);
  // Root flow is Q_perf, root pressure P_perf.
  EXPECT_NEAR(t.flow[t.rootSegment()], p.perfusion_flow, 1e-9 * p.perfusion_flow);
  EXPECT_EQ(t.pressure[0], p.perfusion_pressure);
}

INSTANTIATE_TEST_SUITE_P(Seeds, GrownTree, ::testing::Values(1u, 2u, 3u));

TEST(Physics, SplitRatiosFollowEquations11And12) {
  PhysicsParameters p;
  p.murray_exponent = 2.7;
  const PowerKernel k(p);
  const double na = 3, Ra = 2.5, nb = 7, Rb = 0.9;
  const auto s = k.split(na, Ra, nb, Rb);
  const double ratio = std::pow(na * Ra / (nb * Rb), 0.25);  // r_a / r_b, eq. 12
  EXPECT_NEAR(s.beta_a / s.beta_b, ratio, 1e-12);
  EXPECT_NEAR(std::pow(s.beta_a, 2.7) + std::pow(s.beta_b, 2.7), 1.0, 1e-12);  // eq. 11
}

TEST(Physics, RootRadiusFromPressureDrop) {
  PhysicsParameters p;
  const double q = 10, R = 3;
  const double r = rootRadius(p, q, R);
  // ΔP = Q · 8ηR̃/(π r⁴) must equal P_perf − P_term.
  EXPECT_NEAR(q * 8 * p.viscosity * R / (std::numbers::pi * std::pow(r, 4)), p.perfusion_pressure - p.terminal_pressure,
              1e-9 * (p.perfusion_pressure - p.terminal_pressure));
}

}  // namespace
