// CCO forests: inlets that compete for one kind's terminals, fixed flow shares, and an arterial
// and a venous tree filling one domain. Every tree of every forest meets the invariants of a
// single CCO tree, and no vessel of one tree overlaps a vessel of another (brute force).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <numbers>

#include "core/units.hpp"
#include "domain/growth_domain.hpp"
#include "grow/cco/grower.hpp"
#include "physics/hemodynamics.hpp"
#include "test_support.hpp"
#include "tree_checks.hpp"

using namespace angiosynth;

namespace {

CcoOptions options(std::int64_t n, std::uint64_t seed) {
  CcoOptions o;
  o.terminals = n;
  o.physics.perfusion_flow = 500 * 1e3 / 60;
  o.physics.perfusion_pressure = 100 * kPaPerMmHg;
  o.physics.terminal_pressure = 60 * kPaPerMmHg;
  o.physics.total_terminals = n;
  o.seed = seed;
  return o;
}

CcoInlet inlet(const Vec3& root, int system, double share = 0, double p_root = 100 * kPaPerMmHg, double p_term = 60 * kPaPerMmHg) {
  CcoInlet in;
  in.root_mm = root;
  in.system = system;
  in.share = share;
  in.root_pressure = p_root;
  in.terminal_pressure = p_term;
  return in;
}

// Hemodynamics and geometry of every tree (terminal flow Q/N of its system), and no overlap
// within or across trees on the assembled forest.
void expectForestInvariants(const std::vector<VascularTree>& trees, const std::vector<CcoInlet>& inlets, const CcoOptions& o, const GrowthDomain& d) {
  ASSERT_EQ(trees.size(), inlets.size());
  VascularTree forest;
  for (std::size_t k = 0; k < trees.size(); ++k) {
    SCOPED_TRACE("tree " + std::to_string(k));
    test::expectHemodynamicInvariants(trees[k], inletPhysics(o.physics, inlets[k].root_pressure, inlets[k].terminal_pressure),
                                      trees[k].terminalCount(), o.physics.perfusion_flow / double(o.terminals));
    test::expectGeometry(trees[k], d);
    EXPECT_EQ(trees[k].position[0], inlets[k].root_mm);
    forest.appendTree(trees[k], int(k));
  }
  EXPECT_EQ(test::bruteForceIntersections(forest), 0);
}

TEST(CcoForest, TwoInletsCompeteForOneKindsTerminalsAndEveryTreeMeetsItsInvariants) {
  const auto d = GrowthDomain::analytic(DomainShape::Disc, 20, 0.1);
  const auto o = options(600, 3);
  const std::vector<CcoInlet> inlets{inlet(d.center() + Vec3(-20, 0, 0), 0), inlet(d.center() + Vec3(20, 0, 0), 0)};
  GrowthReport rep;
  const auto trees = growCcoForest(d, o, inlets, rep);
  expectForestInvariants(trees, inlets, o, d);
  EXPECT_EQ(rep.intersecting_pairs, 0);
  // The two trees share the 600 terminals; each wins a territory around its own inlet.
  EXPECT_EQ(trees[0].terminalCount() + trees[1].terminalCount(), 600);
  EXPECT_GT(trees[0].terminalCount(), 30);
  EXPECT_GT(trees[1].terminalCount(), 30);
  for (int k = 0; k < 2; ++k) {
    double x = 0;
    for (std::int32_t i = 1; i < trees[k].nodeCount(); ++i)
      if (trees[k].isTerminal(i)) x += (trees[k].position[i].x - d.center().x) / trees[k].terminalCount();
    EXPECT_LT(k == 0 ? x : -x, 0) << "tree " << k << " mean terminal x " << x;
  }
}

TEST(CcoForest, FixedSharesGiveEachInletItsQuotaOfTerminalsAndFlow) {
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, 10, 0.25);
  const auto o = options(500, 5);
  const Vec3 c = d.center();
  const std::vector<CcoInlet> inlets{inlet(c + Vec3(0, 10, 0), 0, 0.5), inlet(c + Vec3(10, 0, 0), 0, 0.3), inlet(c + Vec3(0, -10, 0), 0, 0.2)};
  GrowthReport rep;
  const auto trees = growCcoForest(d, o, inlets, rep);
  expectForestInvariants(trees, inlets, o, d);
  const std::int64_t quota[] = {250, 150, 100};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(trees[k].terminalCount(), quota[k]);
    EXPECT_NEAR(trees[k].flow[trees[k].rootSegment()], inlets[k].share * o.physics.perfusion_flow, 1e-9 * o.physics.perfusion_flow);
  }
}

TEST(CcoForest, ArteryAndVeinFillOneDomainWithoutTouchingAndTheVeinDrains) {
  // The density of examples/cco_artery_vein_3d.toml: 40 terminals per cm^3 of each kind.
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, 19, 0.4);
  const auto o = options(1200, 7);
  const Vec3 c = d.center();
  const double s = std::sqrt(19.0 * 19.0 - 4.0);
  const std::vector<CcoInlet> inlets{inlet(c + Vec3(-2, s, 0), 0), inlet(c + Vec3(2, s, 0), 1, 0, 5 * kPaPerMmHg, 20 * kPaPerMmHg)};
  GrowthReport rep;
  const auto trees = growCcoForest(d, o, inlets, rep);
  expectForestInvariants(trees, inlets, o, d);
  EXPECT_EQ(rep.intersecting_pairs, 0);
  // Each kind has its own N terminals and carries the whole flow, in through the artery and out
  // through the vein; the vein, with the smaller pressure drop, is the wider.
  for (const auto& t : trees) {
    EXPECT_EQ(t.terminalCount(), 1200);
    EXPECT_NEAR(t.flow[t.rootSegment()], o.physics.perfusion_flow, 1e-9 * o.physics.perfusion_flow);
  }
  const auto& vein = trees[1];
  EXPECT_LT(vein.pressure[0], vein.pressure[vein.rootSegment()]);
  EXPECT_GT(vein.radius[vein.rootSegment()], trees[0].radius[trees[0].rootSegment()]);
  // Both fill the whole sphere: every octant holds terminals of both kinds.
  for (const auto& t : trees) {
    int octants[8] = {};
    for (std::int32_t i = 1; i < t.nodeCount(); ++i)
      if (t.isTerminal(i)) {
        const Vec3 p = t.position[i] - c;
        ++octants[(p.x > 0) + 2 * (p.y > 0) + 4 * (p.z > 0)];
      }
    for (int q = 0; q < 8; ++q) EXPECT_GT(octants[q], 1200 / 8 / 2) << "octant " << q;
  }
}

TEST(CcoForest, SameSeedSameForestWhateverTheThreads) {
  const auto d = GrowthDomain::analytic(DomainShape::Cube, 20, 0.4);
  const auto o = options(400, 11);
  const Vec3 c = d.center();
  const std::vector<CcoInlet> inlets{inlet(c + Vec3(-10, 0, 0), 0), inlet(c + Vec3(10, 0, 0), 0),
                                     inlet(c + Vec3(0, 10, 0), 1, 0, 5 * kPaPerMmHg, 20 * kPaPerMmHg)};
  const auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    GrowthReport rep;
    return growCcoForest(d, o, inlets, rep);
  };
  const auto a = run(1), b = run(2);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].nodeCount(), b[k].nodeCount());
    for (std::int32_t i = 0; i < a[k].nodeCount(); ++i) {
      EXPECT_EQ(a[k].position[i], b[k].position[i]);
      EXPECT_EQ(a[k].radius[i], b[k].radius[i]);
    }
  }
}

TEST(CcoForest, QuotasFollowTheSharesAndSumToTheTerminals) {
  EXPECT_EQ(terminalQuotas({0.5, 0.5}, 1001), (std::vector<std::int64_t>{501, 500}));
  EXPECT_EQ(terminalQuotas({0.2, 0.3, 0.5}, 7), (std::vector<std::int64_t>{1, 2, 4}));  // 1.4, 2.1, 3.5
  EXPECT_EQ(terminalQuotas({1.0 / 3, 1.0 / 3, 1.0 / 3}, 100), (std::vector<std::int64_t>{34, 33, 33}));
  // With an inlet that wins territory, the fixed ones get their share rounded down.
  EXPECT_EQ(terminalQuotas({0.25, 0}, 10), (std::vector<std::int64_t>{2, 0}));
}

}  // namespace
