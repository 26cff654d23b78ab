// Faithful CCO (Kerautret et al. (OpenCCO)): Kamiya's bifurcation, domains, and the invariants of real grown trees
// in 3D, 2D and a non-convex mask.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/units.hpp"
#include "domain/growth_domain.hpp"
#include "grow/cco/grower.hpp"
#include "grow/common/bifurcation_optimizer.hpp"
#include "grow/common/intersections.hpp"
#include "grow/common/kamiya.hpp"
#include "grow/common/spread_bifurcation.hpp"
#include "core/segment_index.hpp"
#include "physics/hemodynamics.hpp"
#include "test_support.hpp"
#include "tree_checks.hpp"

using namespace angiosynth;

namespace {

// Seed 000 §5 / Karch 1999 physics: 500 mL/min at 100 → 60 mmHg, 3.6 cP, γ = 3.
CcoOptions karch(std::int64_t n, const GrowthDomain& d, std::uint64_t seed = 1) {
  CcoOptions o;
  o.terminals = n;
  if (d.shape() != DomainShape::Mask) o.root_mm = d.defaultRoot();
  o.physics.perfusion_flow = 500 * 1e3 / 60;
  o.physics.perfusion_pressure = 100 * kPaPerMmHg;
  o.physics.terminal_pressure = 60 * kPaPerMmHg;
  o.physics.total_terminals = n;
  o.seed = seed;
  return o;
}

// A map of the given size whose voxel (i,j,k) holds value(i,j,k).
template <class F>
DemandMap voxelMap(std::array<std::int32_t, 3> dims, double voxel_mm, F&& value) {
  DemandMap m;
  m.dims = dims;
  m.voxel_mm = voxel_mm;
  m.demand.assign(m.voxelCount(), 0.0f);
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i) m.demand[m.flat(i, j, k)] = static_cast<float>(value(i, j, k));
  return m;
}

// A disc tree of 1500 terminals (seed 3) with the grower's optimiser for it (on the volume, the
// domain checked on results only) and a grid of its segments: the set-up of tests that check
// the grower's claims about points drawn beside its vessels.
struct GrownDisc {
  GrowthDomain d = GrowthDomain::analytic(DomainShape::Disc, 40, 0.2);
  CcoOptions o = karch(1500, d, 3);
  GrowthReport rep;
  VascularTree t = growCco(d, o, rep);
  PhysicsParameters volume = [&] {
    PhysicsParameters v = o.physics;
    v.cost_radius_exponent = 2;
    v.cost_length_exponent = 1;
    return v;
  }();
  BifurcationOptimizer opt{t, volume, nullptr, 0.0};
  SegmentIndex index{d.lo(), d.hi(), true};
  GrownDisc() { index.refresh(t, true); }
};

}  // namespace

TEST(Kamiya, SolvesKamiyasLawAndPressureDropsAndStopsAtTheVolumeWeightedCentre) {
  KamiyaProblem p;
  p.x0 = Vec3(0, 0, 0);
  p.x1 = Vec3(-3, 10, 0.5);
  p.x2 = Vec3(3, 10, -0.5);
  p.f1 = 3;
  p.f2 = 1;
  const auto k = kamiyaBifurcation(p, 200, 1e-12);
  ASSERT_TRUE(k.converged);
  EXPECT_FALSE(k.merged);
  const double f0 = p.f1 + p.f2;
  // Kamiya's law r0⁶/f0 = r1⁶/f1 + r2⁶/f2.
  EXPECT_NEAR(std::pow(k.r0, 6) / f0, std::pow(k.r1, 6) / p.f1 + std::pow(k.r2, 6) / p.f2, 1e-9 * std::pow(k.r0, 6) / f0);
  // The pressure drops of step 1 (equal starting radii, x at the midpoint of x0–x1) are reproduced.
  const Vec3 mid = (p.x0 + p.x1) * 0.5;
  const double l0 = distance(p.x0, mid), l1 = distance(p.x1, mid), l2 = distance(p.x2, mid);
  const double d1 = f0 * l0 + p.f1 * l1, d2 = f0 * l0 + p.f2 * l2;  // radii 1
  EXPECT_NEAR(f0 * l0 / std::pow(k.r0, 4) + p.f1 * l1 / std::pow(k.r1, 4), d1, 1e-8 * d1);
  EXPECT_NEAR(f0 * l0 / std::pow(k.r0, 4) + p.f2 * l2 / std::pow(k.r2, 4), d2, 1e-8 * d2);
  // Eq. (13) at its fixed point: Σ r_i² (x_i − x)/l_i = 0, and x lies in the plane of the points.
  Vec3 pull(0, 0, 0);
  const Vec3 xs[3] = {p.x0, p.x1, p.x2};
  const double a[3] = {k.r0 * k.r0, k.r1 * k.r1, k.r2 * k.r2};
  for (int i = 0; i < 3; ++i) pull = pull + (xs[i] - k.x) * (a[i] / distance(xs[i], k.x));
  EXPECT_LT(norm(pull), 1e-8 * a[0]);
  const Vec3 n = cross(p.x1 - p.x0, p.x2 - p.x0);
  EXPECT_NEAR(dot(k.x - p.x0, n) / norm(n), 0.0, 1e-9);
  // The thicker branch pulls the bifurcation towards itself: r1 > r2 for f1 > f2.
  EXPECT_GT(k.r1, k.r2);
}

TEST(Kamiya, ATerminalBesideANodeMergesIntoIt) {
  // A new terminal almost on the distal node of a thick segment: the optimum is that node.
  KamiyaProblem q;
  q.x0 = Vec3(0, 0, 0);
  q.x1 = Vec3(0, 10, 0);
  q.x2 = Vec3(0.01, 10.5, 0);
  q.f1 = 50;
  q.f2 = 1;
  const auto m = kamiyaBifurcation(q, 200, 1e-12);
  ASSERT_TRUE(m.merged);
  // The bifurcation is one of the three points, the one where the weighted Fermat condition
  // |Σ_{i≠j} r_i² u_ij| ≤ r_j² holds for the radii found.
  const Vec3 xs[3] = {q.x0, q.x1, q.x2};
  const double a[3] = {m.r0 * m.r0, m.r1 * m.r1, m.r2 * m.r2};
  int at = -1;
  for (int j = 0; j < 3; ++j)
    if (m.x == xs[j]) at = j;
  ASSERT_GE(at, 0);
  Vec3 pull(0, 0, 0);
  for (int i = 0; i < 3; ++i)
    if (i != at) pull = pull + (xs[i] - xs[at]) * (a[i] / distance(xs[i], xs[at]));
  EXPECT_LE(norm(pull), a[at]);
}

TEST(GrowthDomain, MaskDepthFromOpenVdbMatchesTheBallItVoxelises) {
  // A ball of radius 12 voxels; depth at voxel centres against the exact distance to the sphere
  // (the voxelised border lies within half a voxel of it).
  const Vec3 c(10, 10, 10);
  const auto m = voxelMap({40, 40, 40}, 0.5, [&](int i, int j, int k) { return distance(Vec3(i + 0.5, j + 0.5, k + 0.5) * 0.5, c) < 6.0; });
  const auto d = GrowthDomain::mask(m, false);
  EXPECT_EQ(d.dimension(), 3);
  EXPECT_NEAR(d.measure(), 4.0 / 3.0 * std::numbers::pi * 216, 0.03 * 4.0 / 3.0 * std::numbers::pi * 216);
  // Within four voxels of the border (where vessel radii are compared with it) the depth follows
  // the voxelised border to half a voxel; deeper, fast sweeping's first-order error only ever makes it
  // smaller, which keeps vessels further inside, never outside.
  double worst_band = 0, worst_over = 0;
  for (double r = 0; r <= 8; r += 0.25)
    for (const Vec3 dir : {Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0.6, 0.8, 0), Vec3(0.48, 0.6, 0.64)}) {
      const double exact = 6.0 - r, got = d.depth(c + dir * r);
      if (std::abs(exact) <= 2.0) worst_band = std::max(worst_band, std::abs(got - exact));
      worst_over = std::max(worst_over, got - exact);
    }
  EXPECT_LT(worst_band, 0.25);  // half a voxel: the staircase of the voxelised sphere
  EXPECT_LT(worst_over, 0.25);
  EXPECT_GT(d.depth(c), 4.5);
  EXPECT_LT(d.depth(c + Vec3(7, 0, 0)), 0);
}

TEST(Cco, SphereTreeMeetsEveryConstraintAndHemodynamicInvariant) {
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));  // 100 cm³
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 50);
  const auto o = karch(4000, d);
  GrowthReport rep;
  const auto t = growCco(d, o, rep);
  PhysicsParameters p = o.physics;
  test::expectHemodynamicInvariants(t, p, 4000);
  test::expectGeometry(t, d);
  EXPECT_EQ(rep.intersecting_pairs, 0);
  // Mean radius falls with the bifurcation level over the first levels (Kerautret et al. (OpenCCO) Fig. 6–7),
  // from a root of about a millimetre (Karch 1999: 1.3–1.5 mm) to terminals under 0.15 mm.
  // Volume-optimal bifurcations carry trunks deep, with side branches off them, so beyond
  // level 8 the means level off (within 10 % of each other) instead of falling further.
  std::vector<double> sum(64, 0.0), count(64, 0.0);
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) sum[t.depth[i] - 1] += t.radius[i], count[t.depth[i] - 1] += 1;
  for (int l = 1; l <= 8; ++l) EXPECT_LT(sum[l] / count[l], sum[l - 1] / count[l - 1]) << "level " << l;
  for (int l = 9; l <= 20; ++l) EXPECT_LT(sum[l] / count[l], 1.1 * sum[8] / count[8]) << "level " << l;
  EXPECT_GT(rep.root_radius_mm, 0.8);
  EXPECT_LT(rep.root_radius_mm, 2.0);
  double terminal_radius = 0;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i)
    if (t.isTerminal(i)) terminal_radius += t.radius[i] / 4000;
  EXPECT_LT(terminal_radius, 0.15);
}

TEST(Cco, NuDoublesOnlyWhereAskedAndOnlyInSpace) {
  // By default a point none of its ν nearest segments can take is dropped; with
  // max_closest_neighbours above ν the sphere doubles ν for such points, the disc never does.
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));
  const auto sphere = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 50);
  const auto disc = GrowthDomain::analytic(DomainShape::Disc, 40, 0.2);
  for (const auto* d : {&sphere, &disc})
    for (const int max_nu : {20, 80}) {
      auto o = karch(2000, *d);
      o.max_neighbours = max_nu;
      GrowthReport rep;
      const auto t = growCco(*d, o, rep);
      EXPECT_EQ(rep.intersecting_pairs, 0);
      EXPECT_EQ(rep.short_segments, 0);
      if (max_nu > 20 && d == &sphere)
        EXPECT_GT(rep.neighbour_doublings, 0);
      else
        EXPECT_EQ(rep.neighbour_doublings, 0) << (d == &sphere ? "sphere" : "disc") << " with up to " << max_nu;
    }
}

TEST(Cco, ATrunkBlockedOnlyBySmallVesselsIsLengthenedNotLeftShort) {
  // At 20,000 terminals in this sphere the final check met a trunk (r 1.03 mm, 10,431
  // terminals) 1.89 mm long that no slide could lengthen past 2r, each blocked by a single
  // terminal segment; both children were too large to give up, and it was left short. The
  // small vessels in the way are now removed and regrown instead.
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 50);
  const auto o = karch(20000, d);
  GrowthReport rep;
  const auto t = growCco(d, o, rep);
  EXPECT_EQ(rep.short_segments, 0);
  EXPECT_EQ(rep.intersecting_pairs, 0);
  EXPECT_EQ(t.terminalCount(), 20000);
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) ASSERT_GT(t.length[s], 2 * t.radius[s]) << "segment " << s;
}

TEST(Cco, ABifurcationBetweenShortSegmentsIsSpreadUntilEachIsLongEnough) {
  // The repair's last free move for a short trunk whose sibling is as short (seen near the
  // roots of organ-scale trees grown in parts, where each such trunk cost a side branch of
  // thousands of terminals): every bifurcation of a real tree, its trunk and larger child made
  // short (r = 0.55 l), is spread so that all three segments reach 2.05 r.
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 50);
  GrowthReport rep;
  const auto t = growCco(d, karch(2000, d), rep);
  int spread = 0, tried = 0;
  auto s = t;
  for (std::int32_t v = 1; v < t.nodeCount(); ++v) {
    if (t.isTerminal(v)) continue;
    s.radius = t.radius;
    const auto larger = s.terminals[s.child0[v]] >= s.terminals[s.child1[v]] ? s.child0[v] : s.child1[v];
    for (const auto x : {v, larger}) s.radius[x] = 0.55 * s.length[x];
    const auto lengths = [&](const Vec3& q) {
      return std::array<double, 3>{distance(q, s.position[s.parent[v]]) / s.radius[v], distance(q, s.position[s.child0[v]]) / s.radius[s.child0[v]],
                                   distance(q, s.position[s.child1[v]]) / s.radius[s.child1[v]]};
    };
    ++tried;
    const auto q = spreadBifurcation(s, v);
    if (!q) continue;
    ++spread;
    for (const double l : lengths(*q)) ASSERT_GE(l, 2 * kSpreadSettled) << "bifurcation " << v;
    const double thickest = std::max({s.radius[v], s.radius[s.child0[v]], s.radius[s.child1[v]]});
    EXPECT_LE(distance(*q, s.position[v]), 2 * kSpreadLength * thickest) << "bifurcation " << v;
  }
  EXPECT_GE(spread, 0.99 * tried) << spread << " of " << tried;
  // Nothing to do where every segment is long enough, and no answer where the ends leave no
  // room within 2.1 r (the nearest room is 2 away, the pushes end 3.1 away).
  const auto long_enough = [&](std::int32_t x) { return t.length[x] >= 2 * kSpreadSettled * t.radius[x]; };
  for (std::int32_t v = 1; v < t.nodeCount(); ++v) {
    if (!t.isTerminal(v) && long_enough(v) && long_enough(t.child0[v]) && long_enough(t.child1[v])) {
      ASSERT_FALSE(spreadBifurcation(t, v)) << "bifurcation " << v;
    }
  }
  VascularTree cramped;
  cramped.addNode(Vec3(0, 0, 0), -1);
  const auto mid = cramped.addNode(Vec3(1, 0, 0), 0);
  cramped.addNode(Vec3(2, 0, 0), mid);
  cramped.addNode(Vec3(1, 3, 0), mid);
  cramped.radius.assign(4, 1.0);
  EXPECT_FALSE(spreadBifurcation(cramped, mid));
}

TEST(Cco, AnAncestorKeptBackByATinyVesselGrowsOnAndTheRepairRegrowsTheVessel) {
  // With seed 4 in this sphere, trunks of hundreds to thousands of terminals thickened into
  // vessels of 1 to 27 terminals beside them and refused every connection below them: 188,186
  // connections were refused, and at 50,000 terminals (seed 3) growth took 377 s instead of
  // 12. After 8 refusals such an ancestor no longer counts vessels of at most 8 terminals or
  // 1/64 of its own; the final check finds the overlap and the repair regrows the small vessel.
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 50);
  const auto o = karch(20000, d, 4);
  GrowthReport rep;
  const auto t = growCco(d, o, rep);
  EXPECT_LT(rep.rejected_intersection, 120000);  // 28,822 with the rule
  EXPECT_GT(rep.repaired_terminals, 0);
  EXPECT_EQ(rep.short_segments, 0);
  EXPECT_EQ(rep.intersecting_pairs, 0);
  EXPECT_EQ(t.terminalCount(), 20000);
  test::expectHemodynamicInvariants(t, o.physics, 20000);
}

TEST(Cco, DiscTreeIsPlanarAndMeetsEveryConstraint) {
  const auto d = GrowthDomain::analytic(DomainShape::Disc, 40, 0.2);
  const auto o = karch(1500, d, 3);
  GrowthReport rep;
  const auto t = growCco(d, o, rep);
  test::expectHemodynamicInvariants(t, o.physics, 1500);
  test::expectGeometry(t, d);
  for (const auto& p : t.position) ASSERT_EQ(p.z, d.planeZ());
}

TEST(Cco, ASegmentHiddenInThePlaneIsReachedOnlyAcrossAVessel) {
  // The disc tree skips the segments a vessel separates from a drawn point (separatedInPlane)
  // on the claim that every bifurcation CCO tries for them crosses that vessel. Points drawn
  // outside the vessels of a grown tree: Kamiya's point and the exact optimiser's (from it, as
  // the grower refines) for each hidden segment among the 40 nearest must cross a vessel that
  // shares no end with the segment.
  GrownDisc disc;
  const auto& d = disc.d;
  const auto& t = disc.t;
  const auto& opt = disc.opt;
  auto& index = disc.index;
  EXPECT_GT(disc.rep.hidden_segments, 1000) << "the grower skips hidden segments";
  Rng rng(5, 0, Stage::Growth);
  std::vector<std::pair<double, std::int32_t>> near;
  int hidden = 0, points = 0, uncrossed = 0;
  const auto crossesAVessel = [&](std::int32_t s, const Vec3& b, const Vec3& p) {
    const Vec3 x0 = t.position[t.parent[s]], x1 = t.position[s];
    for (std::int32_t y = 1; y < t.nodeCount(); ++y) {
      if (y == s || t.parent[y] == t.parent[s] || t.parent[y] == s || y == t.parent[s]) continue;  // an end at x0 or x1
      const Vec3 y0 = t.position[t.parent[y]], y1 = t.position[y];
      if (crossInPlane(x0, b, y0, y1) || crossInPlane(b, x1, y0, y1) || crossInPlane(b, p, y0, y1)) return true;
    }
    return false;
  };
  while (points < 300) {
    const Vec3 p = d.sample(rng);
    index.nearest(t, p, 40, near);
    if (near.front().first <= t.radius[near.front().second]) continue;  // inside a vessel
    ++points;
    for (const auto& [dist, s] : near) {
      if (!separatedInPlane(t, s, p, near, 40)) continue;
      ++hidden;
      KamiyaProblem kp;
      kp.x0 = t.position[t.parent[s]];
      kp.x1 = t.position[s];
      kp.x2 = p;
      kp.f1 = t.terminals[s];
      const auto k = kamiyaBifurcation(kp);
      const bool kamiya = k.converged && !k.merged;
      if (kamiya && !crossesAVessel(s, k.x, p)) ++uncrossed;
      const auto exact = opt.optimise(s, p, 4, kamiya ? &k.x : nullptr);
      if (exact.valid && !crossesAVessel(s, exact.bifurcation, p)) ++uncrossed;
    }
  }
  EXPECT_GT(hidden, 1000) << "hidden segments are common on the disc";
  EXPECT_EQ(uncrossed, 0) << "of " << hidden << " hidden segments";
}

TEST(Cco, APointBesideAVesselCanConnectOnlyBesideThatVessel) {
  // The grower does not cost connections of a drawn point whose nearest vessel surface lies
  // within half a terminal's radius (crowdedOut), except on the segments beside that vessel: the
  // new terminal's vessel ends at the point and would touch it. Points drawn so near a vessel of
  // a grown disc tree: the exact optimiser's connection on every other segment among the 20
  // nearest must give the new terminal a radius that reaches the vessel (0 of 4898; with the
  // whole radius instead of half, 153 of 4916 would not).
  GrownDisc disc;
  const VascularTree& t = disc.t;
  EXPECT_GT(disc.rep.crowded_segments, 500) << "the grower skips crowded-out segments";
  std::vector<double> terminal_radii;
  for (std::int32_t s = 1; s < t.nodeCount(); ++s)
    if (t.isTerminal(s)) terminal_radii.push_back(t.radius[s]);
  std::nth_element(terminal_radii.begin(), terminal_radii.begin() + terminal_radii.size() / 2, terminal_radii.end());
  const double crowd = 0.5 * terminal_radii[terminal_radii.size() / 2];
  Rng rng(7, 0, Stage::Growth);
  std::vector<std::pair<double, std::int32_t>> near;
  int points = 0, tried = 0, clear = 0;
  while (points < 300) {
    const Vec3 p = disc.d.sample(rng);
    disc.index.nearest(t, p, 20, near);
    const auto [dy, y] = near.front();
    const double gap = dy - t.radius[y];
    if (gap <= 0 || gap >= crowd) continue;  // inside a vessel, or not crowded
    ++points;
    for (const auto& [ds, s] : near) {
      if (s == y || s == t.parent[y] || t.parent[s] == t.parent[y] || t.parent[s] == y) continue;  // beside y
      const auto c = disc.opt.optimise(s, p, 4);
      if (!c.valid) continue;
      ++tried;
      if (!(dy < disc.opt.radiiAt(s, c.bifurcation, p)[2] + t.radius[y])) ++clear;
    }
  }
  EXPECT_GT(tried, 1000);
  EXPECT_EQ(clear, 0) << "of " << tried << " connections from crowded points";
}

TEST(Cco, TheProximalNodeTestAgreesWithTheExactCost) {
  // The grower does not refine a trial whose Kamiya point merged into the split segment's
  // proximal node when optimumAtProximalNode says the exact optimum is there too. On a grown
  // disc tree, for drawn points outside the vessels and their 8 nearest segments: where the test
  // says so, no point on small circles around the node is cheaper than the node (782 cases;
  // without the test's 1 % margin, 3 would be), and the optimiser's result after 100 steps from
  // the midpoint rarely is (the exact cost is not convex; 0 here); where it says not, one of
  // them nearly always is (all but 54 of 1,618, inside the margin).
  GrownDisc disc;
  const auto& t = disc.t;
  const auto& opt = disc.opt;
  Rng rng(11, 0, Stage::Growth);
  std::vector<std::pair<double, std::int32_t>> near;
  int at_node = 0, away = 0, wrong = 0, elsewhere = 0, not_beaten = 0;
  for (int points = 0; points < 300;) {
    const Vec3 p = disc.d.sample(rng);
    disc.index.nearest(t, p, 8, near);
    if (near.front().first <= t.radius[near.front().second]) continue;
    ++points;
    for (const auto& [dist, s] : near) {
      const Vec3 x0 = t.position[t.parent[s]];
      const double node = opt.costAt(s, x0, p);
      const double scale = distance(x0, t.position[s]) + distance(x0, p);
      bool cheaper_around = false;
      for (double h : {1e-4 * scale, 1e-7 * scale})
        for (int a = 0; a < 64; ++a) {
          const double phi = 2 * std::acos(-1.0) * a / 64;
          cheaper_around |= opt.costAt(s, x0 + Vec3(std::cos(phi), std::sin(phi), 0) * h, p) < node;
        }
      const auto o = opt.optimise(s, p, 100);
      const bool cheaper_found = o.valid && o.cost < node;
      if (opt.optimumAtProximalNode(s, p)) {
        ++at_node;
        wrong += cheaper_around;
        if (cheaper_found) {
          ++elsewhere;
          EXPECT_LT(node - o.cost, 1e-4 * node);
        }
      } else {
        ++away;
        not_beaten += !cheaper_around && !cheaper_found;
      }
    }
  }
  EXPECT_GT(at_node, 500) << "optimum at the node is common on the disc";
  EXPECT_EQ(wrong, 0) << "of " << at_node;
  EXPECT_LE(elsewhere, at_node / 100);
  EXPECT_LE(not_beaten, away / 20) << "of " << away;
}

TEST(Cco, NonConvexMaskKeepsEveryVesselInsideTheMask) {
  // An L-shaped slab: the straight line between its arms leaves the domain.
  const auto m =
      voxelMap({60, 60, 16}, 0.5, [](int i, int j, int k) { return k >= 2 && k < 14 && j >= 2 && j < 58 && i >= 2 && i < 58 && (i < 22 || j < 22); });
  const auto d = GrowthDomain::mask(m, false);
  auto o = karch(600, d, 5);
  o.root_mm = Vec3(1.0, 1.0, 4.0);  // on the corner face of the L
  GrowthReport rep;
  const auto t = growCco(d, o, rep);
  test::expectHemodynamicInvariants(t, o.physics, 600);
  test::expectGeometry(t, d);
  // Independently of the depth map: every centreline sample lies in a mask voxel.
  std::int64_t outside = 0;
  for (std::int32_t s = 1; s < t.nodeCount(); ++s)
    for (int k = 0; k <= 32; ++k) {
      const Vec3 p = t.position[t.parent[s]] + (t.position[s] - t.position[t.parent[s]]) * (k / 32.0);
      if (!m.perfusable(p)) ++outside;
    }
  EXPECT_EQ(outside, 0);
  // Terminals reach the far end of both arms (x > 11 mm, or y > 11 mm).
  int arm_x = 0, arm_y = 0;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    if (!t.isTerminal(i)) continue;
    arm_x += t.position[i].x > 11;
    arm_y += t.position[i].y > 11;
  }
  EXPECT_GT(arm_x, 100);
  EXPECT_GT(arm_y, 100);
}

TEST(Cco, DemandWeightedSamplingPutsTerminalsWhereDemandIsHigh) {
  // A cube map whose upper half in x asks for nine times the demand of the lower half.
  const auto m = voxelMap({40, 40, 40}, 0.5, [](int i, int j, int k) {
    const bool in = std::min({i, j, k}) >= 1 && std::max({i, j, k}) < 39;
    return in ? (i < 20 ? 1.0 : 9.0) : 0.0;
  });
  const auto share_high = [&](bool weighted) {
    const auto d = GrowthDomain::mask(m, weighted);
    auto o = karch(800, d, 7);
    o.root_mm = Vec3(10, 0.6, 10);
    GrowthReport rep;
    const auto t = growCco(d, o, rep);
    test::expectGeometry(t, d);
    double high = 0;
    for (std::int32_t i = 1; i < t.nodeCount(); ++i)
      if (t.isTerminal(i)) high += t.position[i].x > 10;
    return high / 800;
  };
  const double uniform = share_high(false), weighted = share_high(true);
  EXPECT_NEAR(uniform, 0.5, 0.06);
  // 90 % of the demand; δ_max, scaled by the local demand, lets the terminals follow it.
  EXPECT_NEAR(weighted, 0.9, 0.04);
}

namespace {
// OpenCCO's set-up: a 20,000 mm³ ball and its constants (13300 Pa, 7980 Pa, 8330 mm³/s,
// 3.6 mPa·s).
GrowthDomain openccoBall() { return GrowthDomain::analytic(DomainShape::Sphere, std::cbrt(3 * 20000.0 / (4 * std::numbers::pi)), 0.3); }
CcoOptions openccoOptions(std::int64_t n, const GrowthDomain& d, std::uint64_t seed) {
  CcoOptions o;
  o.terminals = n;
  o.root_mm = d.defaultRoot();
  o.physics.perfusion_flow = 8330;
  o.physics.perfusion_pressure = 13300;
  o.physics.terminal_pressure = 7980;
  o.physics.viscosity = 3.6e-3;
  o.physics.total_terminals = n;
  o.seed = seed;
  return o;
}
}  // namespace

TEST(Cco, AShortRootSegmentIsLengthenedWithItsChildWhenNeitherAloneHasRoom) {
  // OpenCCO's ball at 4000 terminals, seed 1: the root segment ended 2.04 mm long at r 1.07 mm.
  // Its proximal end is fixed, and sliding its distal end alone left its larger child 0.005 mm
  // short of its own 2r; the distal end now slides on with that child, which keeps its length.
  const auto d = openccoBall();
  const auto o = openccoOptions(4000, d, 1);
  GrowthReport rep;
  const auto t = growCco(d, o, rep);
  EXPECT_EQ(rep.short_segments, 0);
  EXPECT_EQ(rep.intersecting_pairs, 0);
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) ASSERT_GT(t.length[s], 2 * t.radius[s]) << "segment " << s;
}

TEST(Cco, TreesAreAsLightAsOpenCcosInItsOwnSetUp) {
  // OpenCCO's set-up: a 20,000 mm³ ball, its constants (13300 Pa, 7980 Pa beyond 250 terminals,
  // 8330 mm³/s, 3.6 mPa·s), 1000 terminals. OpenCCO's trees carry 289–293 mm³ (its geometry with
  // these physics). Terminals kept from the terminal points (its Algorithm 2) and the exact
  // bifurcations make ours lighter; the §3.3.2 reading with Kamiya's points alone is 10 % heavier.
  const auto d = openccoBall();
  const auto volume = [&](bool from_segments, bool exact, std::uint64_t seed) {
    auto o = openccoOptions(1000, d, seed);
    o.spacing_from = from_segments ? TerminalSpacing::Segments : TerminalSpacing::Terminals;
    o.bifurcation = exact ? BifurcationPoint::Exact : BifurcationPoint::Kamiya;
    GrowthReport rep;
    const auto t = growCco(d, o, rep);
    test::expectGeometry(t, d);
    return treeVolume(t);
  };
  for (std::uint64_t seed : {1, 2}) {
    const double ours = volume(false, true, seed), kamiya = volume(false, false, seed), text = volume(true, false, seed);
    EXPECT_LT(ours, 289.0) << "seed " << seed;
    EXPECT_LT(ours, 0.95 * kamiya) << "seed " << seed;
    EXPECT_GT(text, 1.05 * kamiya) << "seed " << seed;
  }
}

TEST(Cco, SameSeedSameTreeWhateverTheThreads) {
  const auto d = GrowthDomain::analytic(DomainShape::Cube, 30, 0.6);
  const auto o = karch(1000, d, 11);
  const auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    GrowthReport rep;
    return growCco(d, o, rep);
  };
  const auto a = run(1), b = run(2);
  ASSERT_EQ(a.nodeCount(), b.nodeCount());
  for (std::int32_t i = 0; i < a.nodeCount(); ++i) {
    EXPECT_EQ(a.position[i], b.position[i]);
    EXPECT_EQ(a.radius[i], b.radius[i]);
    EXPECT_EQ(a.parent[i], b.parent[i]);
  }
  auto o2 = o;
  o2.seed = 12;
  GrowthReport rep;
  const auto c = growCco(d, o2, rep);
  EXPECT_NE(c.position[1], a.position[1]);
}

TEST(Cco, OrganScaleTreesKeepEveryInvariantAtNearlyTheSameVolume) {
  // Organ scale trades the paper's procedure for a flat cost per terminal: the carried distance
  // threshold, the geometric refresh of relative radii and the refinement of the lightest
  // candidates only. Every constraint and physical law still holds exactly, and the volume stays
  // within 2 % of the faithful tree's (docs/benchmarks.md has it for 10,000 to 1,000,000 terminals).
  const double radius = std::cbrt(3 * 1e5 / (4 * std::numbers::pi));
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, radius, radius / 50);
  auto o = karch(2000, d);
  GrowthReport faithful_report, organ_report;
  const auto faithful = growCco(d, o, faithful_report);
  o.organ_scale = true;
  const auto organ = growCco(d, o, organ_report);
  test::expectHemodynamicInvariants(organ, o.physics, 2000);
  test::expectGeometry(organ, d);
  EXPECT_EQ(organ_report.intersecting_pairs, 0);
  EXPECT_EQ(test::bruteForceIntersections(organ), 0);
  EXPECT_LT(std::abs(treeVolume(organ) / treeVolume(faithful) - 1), 0.02);
  EXPECT_LT(organ_report.rejected_too_close, faithful_report.rejected_too_close / 2);  // the carried threshold
  // The same tree on one thread or two.
  const auto run = [&](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    auto small = karch(500, d, 5);
    small.organ_scale = true;
    GrowthReport rep;
    return growCco(d, small, rep);
  };
  const auto a = run(1), b = run(2);
  ASSERT_EQ(a.nodeCount(), b.nodeCount());
  for (std::int32_t i = 0; i < a.nodeCount(); ++i) {
    EXPECT_EQ(a.position[i], b.position[i]);
    EXPECT_EQ(a.radius[i], b.radius[i]);
  }
}

TEST(Cco, VesselsTooThickForTheirDomainAreRefusedOnTheirCostlyDraws) {
  // Karch et al.'s 500 mL/min into a disc of 2 mm: no second vessel fits beside the first. Draws
  // too close to a vessel are cheap and relax the spacing; the refusal comes from the draws far
  // enough from every vessel that found no connection, each of which costs an optimisation per
  // neighbour, long before the limit on all draws.
  const auto d = GrowthDomain::analytic(DomainShape::Disc, 2, 0.05);
  const auto o = karch(3, d);
  GrowthReport rep;
  try {
    growCco(d, o, rep);
    FAIL() << "the tree fitted";
  } catch (const GrowthError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("5000 points in a row far enough from every vessel"), std::string::npos) << what;
  }
}
