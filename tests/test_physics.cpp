// Physics invariants on real generated trees (Hamarneh & Jassi 2010 §2, §3.7–3.8), each to 1e-9 relative.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/units.hpp"
#include "domain/growth_domain.hpp"
#include "grow/cco/grower.hpp"
#include "morphometry/morphometry.hpp"
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

namespace {

// Each bifurcation's exponent measured from its radii is its band's (parent radius outside the
// ramps at the edges), and every band holds `at_least` of them.
void expectBandsMeasuredBack(const Morphometry& m, const PhysicsParameters& p, int at_least) {
  const auto& edges = p.murray_band_edges;
  std::vector<int> count(edges.size() + 1, 0);
  for (const auto& b : m.bifurcations) {
    std::size_t band = 0;
    bool ramp = false;
    for (double e : edges) {
      ramp = ramp || (b.r_parent_mm > e / 1.05 && b.r_parent_mm < e * 1.05);
      band += b.r_parent_mm >= e;
    }
    if (ramp) continue;
    ++count[band];
    EXPECT_NEAR(b.murray_exponent, p.murray_band_exponents[band], 1e-9) << "bifurcation at node " << b.node << ", parent radius " << b.r_parent_mm;
  }
  for (std::size_t k = 0; k < count.size(); ++k) EXPECT_GE(count[k], at_least) << "band " << k;
}

}  // namespace

// Murray's exponent by parent-radius band (3, 2.7, 2.3 split at 0.1 and 1 mm, as measured from
// arterioles to large arteries): the radii solved under it satisfy Murray's law with the band's γ
// at every bifurcation, flow and Poiseuille to 1e-9, and the exponents measured back from the
// radii (the morphometry's band medians) are the bands'.
TEST(Physics, BandedMurrayExponentsHoldAtEveryBifurcationAndAreMeasuredBack) {
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));  // 100 cm³
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 50);
  CcoOptions o;
  o.terminals = 2000;
  o.root_mm = d.defaultRoot();
  o.physics.perfusion_flow = 500 * 1e3 / 60;
  o.physics.perfusion_pressure = 100 * kPaPerMmHg;
  o.physics.terminal_pressure = 60 * kPaPerMmHg;
  o.physics.total_terminals = o.terminals;
  o.physics.murray_band_edges = {0.1, 1.0};
  o.physics.murray_band_exponents = {3.0, 2.7, 2.3};
  GrowthReport rep;
  const auto t = growCco(d, o, rep);
  test::expectHemodynamicInvariants(t, o.physics, o.terminals);
  EXPECT_EQ(rep.intersecting_pairs, 0);
  expectBandsMeasuredBack(measureTrees(t, {}, {}), o.physics, 5);

  // VascuSynth's oxygen-demand growth under bands set inside its own range of radii: the edges at
  // the 20th and 60th percentiles of the parent radii of its bifurcations under one γ.
  auto ex = test::vascusynthExample(400, 1);
  const auto plain = test::grow(ex);
  std::vector<double> parents;
  for (std::int32_t s = 1; s < plain.nodeCount(); ++s)
    if (!plain.isTerminal(s)) parents.push_back(plain.radius[s]);
  std::sort(parents.begin(), parents.end());
  ex.options.physics.murray_band_edges = {parents[parents.size() / 5], parents[parents.size() * 3 / 5]};
  ex.options.physics.murray_band_exponents = {3.0, 2.6, 2.2};
  const auto v = test::grow(ex);
  test::expectHemodynamicInvariants(v, ex.options.physics, 400);
  expectBandsMeasuredBack(measureTrees(v, {}, {}), ex.options.physics, 3);
}

// The law between bands: the band's γ away from an edge, a linear ramp in log r across ±5 % of it.
TEST(Physics, MurrayLawRampsAcrossBandEdges) {
  PhysicsParameters p;
  p.murray_band_edges = {0.1, 1.0};
  p.murray_band_exponents = {3.0, 2.7, 2.3};
  const MurrayLaw law(p);
  EXPECT_EQ(law.exponentAt(0.0), 3.0);
  EXPECT_EQ(law.exponentAt(0.09), 3.0);
  EXPECT_NEAR(law.exponentAt(0.1), 2.85, 1e-12);
  EXPECT_EQ(law.exponentAt(0.2), 2.7);
  EXPECT_NEAR(law.exponentAt(1.0), 2.5, 1e-12);
  EXPECT_NEAR(law.exponentAt(1.05), 2.3, 1e-12);
  EXPECT_EQ(law.exponentAt(50), 2.3);
  const double lo = 0.1 / 1.05, hi = 0.1 * 1.05;
  EXPECT_NEAR(law.exponentAt(std::sqrt(lo * 0.1)), 3.0 - 0.3 * 0.25, 1e-12);  // a quarter of the way in log r
  EXPECT_NEAR(law.exponentAt(hi), 2.7, 1e-12);
  PhysicsParameters one;
  one.murray_exponent = 2.55;
  EXPECT_EQ(MurrayLaw(one).exponentAt(7), 2.55);
  EXPECT_FALSE(MurrayLaw(one).banded());
}
