// CCO grown by domain decomposition: a trunk, parts grown apart, the join.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>

#include "grow/cco/decomposition.hpp"
#include "physics/hemodynamics.hpp"
#include "tree_checks.hpp"

namespace angiosynth {
namespace {

constexpr double kPaPerMmHg = 133.322;

CcoDecompositionOptions sphereParts(std::int64_t n, int parts, const GrowthDomain& d, std::uint64_t seed = 1) {
  CcoDecompositionOptions o;
  o.cco.terminals = n;
  o.cco.root_mm = d.defaultRoot();
  o.cco.physics.perfusion_flow = 500 * 1e3 / 60;  // Karch et al. 1999
  o.cco.physics.perfusion_pressure = 100 * kPaPerMmHg;
  o.cco.physics.terminal_pressure = 60 * kPaPerMmHg;
  o.cco.seed = seed;
  o.parts = parts;
  return o;
}

// Flow, Murray's law and Poiseuille's drop at every node to 1e-9, nodes inside a vessel included
// (one radius and one flow on both sides), with the whole tree's terminal flow and pressures.
void expectJoinedPhysics(const VascularTree& t, const PhysicsParameters& p, std::int64_t terminals) {
  ASSERT_EQ(t.terminalCount(), terminals);
  const double q = p.perfusion_flow / double(terminals), drop = p.perfusion_pressure - p.terminal_pressure;
  const double k = 8 * p.viscosity / std::numbers::pi;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    if (t.isTerminal(i)) {
      EXPECT_NEAR(t.flow[i], q, 1e-9 * q);
      EXPECT_NEAR(t.pressure[i], p.terminal_pressure, 1e-9 * drop);
      continue;
    }
    const auto a = t.child0[i], b = t.child1[i];
    const double ra = t.radius[a], rb = b >= 0 ? t.radius[b] : 0.0;
    EXPECT_NEAR(t.flow[i], t.flow[a] + (b >= 0 ? t.flow[b] : 0.0), 1e-9 * t.flow[i]);
    EXPECT_NEAR(std::pow(t.radius[i], 3), ra * ra * ra + rb * rb * rb, 1e-9 * std::pow(t.radius[i], 3)) << "node " << i;
    for (auto c : {a, b}) {
      if (c < 0) continue;
      EXPECT_NEAR(t.pressure[c], t.pressure[i] - t.flow[c] * k * t.length[c] / std::pow(t.radius[c], 4), 1e-9 * drop);
    }
  }
}

TEST(CcoDecomposition, JoinedTreeKeepsEveryInvariantAcrossPartBorders) {
  // Four parts of the Karch et al. sphere: the whole tree is one tree of N terminals whose
  // physics holds everywhere, with no vessel touching another (brute force, across parts and
  // against the trunk), none shorter than twice its radius and none leaving the sphere; the parts
  // were grown thicker than the whole tree makes them, and the trunk's vessels stay inside the
  // clearance the parts kept. The domain's voxels are coarse against the terminals' spacing, as
  // at organ scale: the parts grow on grids of half its voxel.
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 30);
  const auto o = sphereParts(3000, 4, d);
  GrowthReport report;
  const auto t = growCcoDecomposed(d, o, report);
  const CcoDecompositionSummary& sum = *report.decomposition;
  PhysicsParameters p = o.cco.physics;
  p.total_terminals = 3000;
  expectJoinedPhysics(t, p, 3000);
  EXPECT_EQ(sum.terminals, 3000);
  EXPECT_EQ(sum.intersecting_pairs, 0);
  EXPECT_EQ(test::bruteForceIntersections(t), 0);
  EXPECT_EQ(sum.short_segments, 0);
  EXPECT_EQ(sum.outside_segments, 0);
  test::expectGeometry(t, d);
  EXPECT_LE(sum.largest_part_scale, 1.0);
  EXPECT_LT(sum.largest_trunk_radius_share, 1.0);
  EXPECT_GT(sum.smallest_part_pressure_share, o.part_pressure_share);
  // Every part vessel lies in its own part's domain: parts cannot meet.
  const CcoTrunk trunk = planCcoTrunk(d, o);
  EXPECT_EQ(trunk.part_voxel_mm, d.frame().voxel_mm / 2);
  std::int64_t sum_n = 0;
  for (auto n : trunk.part_terminals) sum_n += n;
  EXPECT_EQ(sum_n, 3000);
  const CcoPart part = growCcoPart(d, trunk, 2, o);
  Vec3 offset;
  const GrowthDomain pd = ccoPartDomain(d, trunk, 2, offset);
  for (std::int32_t s = 1; s < part.tree.nodeCount(); ++s)
    EXPECT_TRUE(pd.capsuleInside(part.tree.position[part.tree.parent[s]] - offset, part.tree.position[s] - offset, part.tree.radius[s],
                                 part.tree.parent[s] == 0));
  EXPECT_EQ(part.tree.terminalCount(), trunk.part_terminals[2]);
}

TEST(CcoDecomposition, SameTreeWhateverTheThreadsAndWhereverThePartsGrow) {
  // A part grown alone (as an array task would) is the part grown beside the others, and the
  // joined tree is the same on one thread or two.
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 25);
  const auto o = sphereParts(600, 3, d, 4);
  const auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    GrowthReport report;
    return growCcoDecomposed(d, o, report);
  };
  const auto a = run(1), b = run(2);
  ASSERT_EQ(a.nodeCount(), b.nodeCount());
  for (std::int32_t i = 0; i < a.nodeCount(); ++i) {
    EXPECT_EQ(a.position[i], b.position[i]);
    EXPECT_EQ(a.radius[i], b.radius[i]);
  }
  const CcoTrunk trunk = planCcoTrunk(d, o);
  // Voxels of a quarter of the terminals' spacing or less: the parts keep them.
  EXPECT_EQ(trunk.part_voxel_mm, d.frame().voxel_mm);
  std::vector<CcoPart> parts;
  for (int k = 0; k < o.parts; ++k) parts.push_back(growCcoPart(d, trunk, k, o));
  CcoDecompositionSummary sum;
  const auto c = joinCcoParts(d, trunk, parts, o, sum);
  ASSERT_EQ(a.nodeCount(), c.nodeCount());
  for (std::int32_t i = 0; i < a.nodeCount(); ++i) EXPECT_EQ(a.position[i], c.position[i]);
}

TEST(CcoDecomposition, ATrunkTooThickForItsDomainIsRefusedOnItsCostlyDraws) {
  // 500 mL/min into a sphere of 8.79 mm: the trunk's vessels, at the bound on their radii, leave
  // no room for its last terminal. Draws too close to a vessel are cheap and relax the spacing;
  // the refusal comes from the draws far enough from every vessel that found no connection, each
  // of which costs an optimisation per neighbour, long before the trunk's limit on all draws.
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, 8.79, 0.4);
  const auto o = sphereParts(40, 8, d);
  try {
    planCcoTrunk(d, o);
    FAIL() << "the trunk fitted";
  } catch (const GrowthError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("the trunk of 8 parts"), std::string::npos) << what;
    EXPECT_NE(what.find("2000 points in a row far enough from every vessel"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace angiosynth
