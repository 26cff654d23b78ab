// Physics invariants on real generated trees (Hamarneh & Jassi 2010 §2, §3.7–3.8), each to 1e-9 relative.
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
  test::expectHemodynamicInvariants(t, ex.options.physics, 400);
  EXPECT_FALSE(HasFailure());
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
