// Method lsystem, mode lzh (Lázaro 2011): the inverse problem's geometry on random high-level
// parameters, the closed network's flows, tapered vessels in the rasteriser, connectivity.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <queue>
#include <set>

#include "core/rng.hpp"
#include "grow/lsystem/grammar.hpp"
#include "grow/lsystem/lzh.hpp"
#include "grow_file.hpp"
#include "pipeline/volume_outputs.hpp"
#include "raster/ground_truth.hpp"
#include "test_support.hpp"
#include "voxel_components.hpp"

using namespace angiosynth;

namespace {

std::filesystem::path example(const char* name) { return test::sourceDir() / "examples" / name; }

double axisOf(const Vec3& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

// Random but printable high-level parameters: c/d in (1.05, 60), capillaries thinner than their pitch.
LzhParameters randomParameters(Rng& rng, int dimension) {
  LzhParameters p;
  p.dimension = dimension;
  p.block_width = rng.uniform(1, 50);
  p.spacing = p.block_width / rng.uniform(2.05, 61);
  p.start_length = rng.uniform(0.1, 10);
  p.capillary_length = rng.uniform(0.1, 10);
  p.height = 2 * p.start_length + p.capillary_length + rng.uniform(0.5, 60);
  const double c = p.block_width - p.spacing;
  const double pitch = c / (std::exp2(std::ceil(std::log2(c / p.spacing + 1) - 1e-12)) - 1);
  p.capillary_diameter = pitch * rng.uniform(0.05, 0.5);
  p.capillary_wall = p.capillary_diameter * rng.uniform(0, 0.4);
  p.start_diameter = p.capillary_diameter * rng.uniform(1, 8);
  p.start_wall = p.start_diameter * rng.uniform(0, 0.4);
  p.perfusion_flow = rng.uniform(0.01, 10);
  p.perfusion_pressure = 13332;
  return p;
}

// A block by its numbers: dimension, w_b, h, d, L_s, L_c, d_s, d_c (mm).
LzhParameters block(int dim, double w, double h, double d, double ls, double lc, double ds, double dc) {
  LzhParameters p;
  p.dimension = dim;
  p.block_width = w;
  p.height = h;
  p.spacing = d;
  p.start_length = ls;
  p.capillary_length = lc;
  p.start_diameter = ds;
  p.capillary_diameter = dc;
  return p;
}

// Sorted distinct values (to 1e-9) of one coordinate.
std::vector<double> distinct(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  std::vector<double> out;
  for (double x : v)
    if (out.empty() || x - out.back() > 1e-9) out.push_back(x);
  return out;
}

}  // namespace

// Seed 004's oracles on 1000 random parameter sets (500 in one plane, 500 in 3D): capillaries
// equally spaced and at most d apart, the height h, the mirror image, 3 + 2N segments and
// 4 + 2N nodes on every inlet-to-outlet path, a 2^N × 2^N grid in 3D, diameter and wall
// linear in the path length.
TEST(Lzh, RandomHighLevelParametersGiveTheThesisGeometry) {
  Rng rng(2026, 0, Stage::Growth);
  for (int trial = 0; trial < 1000; ++trial) {
    const int dim = trial % 2 ? 3 : 2;
    const LzhParameters p = randomParameters(rng, dim);
    SCOPED_TRACE("trial " + std::to_string(trial));
    const LzhPlan plan = planLzh(p);
    const Vec3 corner(1, 2, dim == 3 ? 3 : 0.5);
    const Forest f = buildLzhNetwork(p, plan, corner, corner.z);
    const VascularTree& t = f.vessels;
    const int up = dim == 3 ? 2 : 1;
    const auto roots = t.roots();
    ASSERT_EQ(roots.size(), std::size_t(plan.leaves + 2));
    const std::int32_t art = roots.front(), ven = roots.back();
    const std::int32_t per_tree = std::int32_t(roots[1] - roots[0]);
    ASSERT_EQ(per_tree, 2 * plan.leaves);

    // Capillaries: their upper ends are the arterial leaves.
    std::vector<double> lat[2];
    for (std::size_t k = 1; k + 1 < roots.size(); ++k) {
      const Vec3& q = t.position[roots[k]];
      lat[0].push_back(q.x);
      if (dim == 3) lat[1].push_back(q.y);
    }
    const double expected_pitch = (p.block_width - p.spacing) / (std::exp2(plan.levels_2d) - 1);
    for (int a = 0; a < (dim == 3 ? 2 : 1); ++a) {
      const auto v = distinct(lat[a]);
      ASSERT_EQ(v.size(), std::size_t(1) << plan.levels_2d) << "a 2^N row (2D) or 2^N × 2^N grid (3D)";
      for (std::size_t i = 1; i < v.size(); ++i) ASSERT_NEAR(v[i] - v[i - 1], expected_pitch, 1e-9);
      ASSERT_LE(v[1] - v[0], p.spacing + 1e-9);
      ASSERT_NEAR(v.front() - axisOf(corner, a), p.spacing / 2, 1e-9);  // half a spacing from the sides
      ASSERT_NEAR(axisOf(corner, a) + p.block_width - v.back(), p.spacing / 2, 1e-9);
    }
    ASSERT_EQ(std::int64_t(lat[0].size()), dim == 3 ? (std::int64_t(1) << (2 * plan.levels_2d)) : (std::int64_t(1) << plan.levels_2d));

    // Height: inlet top to outlet bottom.
    ASSERT_NEAR(axisOf(t.position[art], up) - axisOf(t.position[ven], up), p.height, 1e-9);
    ASSERT_NEAR(axisOf(t.position[art], up), axisOf(corner, up) + p.height, 1e-9);

    // Mirror: venous node i is arterial node i reflected through the mid-plane; same radii.
    const double mid = axisOf(corner, up) + p.height / 2;
    double mirror_error = 0;
    bool same_radii = true;
    for (std::int32_t i = 0; i < per_tree; ++i) {
      const Vec3 a = t.position[art + i], b = t.position[ven + i];
      for (int ax = 0; ax < 3; ++ax)
        mirror_error = std::max(mirror_error, std::abs((ax == up ? 2 * mid - axisOf(a, ax) : axisOf(a, ax)) - axisOf(b, ax)));
      if (i > 0) same_radii = same_radii && t.radius[art + i] == t.radius[ven + i] && t.startRadius(art + i) == t.startRadius(ven + i);
    }
    ASSERT_LE(mirror_error, 1e-9);
    ASSERT_TRUE(same_radii);

    // Paths: from each capillary up to the inlet and down to the outlet. Capillary k hangs from
    // the k-th arterial leaf (breadth-first order) and ends at the k-th venous leaf.
    for (std::size_t k = 1; k + 1 < roots.size(); ++k) {
      const std::int32_t a = art + per_tree - std::int32_t(plan.leaves) + std::int32_t(k - 1);
      const std::int32_t v = ven + per_tree - std::int32_t(plan.leaves) + std::int32_t(k - 1);
      ASSERT_LT(t.child0[a], 0);
      ASSERT_LT(t.child0[v], 0);
      ASSERT_EQ(distance(t.position[a], t.position[roots[k]]), 0.0);
      ASSERT_EQ(distance(t.position[v], t.position[roots[k] + 1]), 0.0);
      int segments = 1;  // the capillary
      for (auto i = a; !t.isRoot(i); i = t.parent[i]) ++segments;
      for (auto i = v; !t.isRoot(i); i = t.parent[i]) ++segments;
      ASSERT_EQ(segments, 3 + 2 * plan.levels);  // nodes: one more
    }

    // Diameter and wall: linear in the path length from the inlet, d_s there, d_c at the leaves.
    std::vector<double> path(std::size_t(per_tree), 0);
    for (std::int32_t i = 1; i < per_tree; ++i) path[i] = path[t.parent[art + i] - art] + t.length[art + i];
    double total = 0;
    for (std::int32_t i = 0; i < per_tree; ++i) total = std::max(total, path[i]);
    double lerp_error = 0;
    for (std::int32_t i = 1; i < per_tree; ++i) {
      const auto s = art + i;
      const double f0 = path[t.parent[s] - art] / total, f1 = path[i] / total;
      for (const double e : {2 * t.startRadius(s) - (p.start_diameter + f0 * (p.capillary_diameter - p.start_diameter)),
                             2 * t.radius[s] - (p.start_diameter + f1 * (p.capillary_diameter - p.start_diameter)),
                             t.wall_start[s] - (p.start_wall + f0 * (p.capillary_wall - p.start_wall)),
                             t.wall[s] - (p.start_wall + f1 * (p.capillary_wall - p.start_wall))})
        lerp_error = std::max(lerp_error, std::abs(e));
    }
    ASSERT_LE(lerp_error, 1e-12);
    // Every branch at θ to the vertical; lengths halve from level to level within a plane.
    for (int n = 0; n + (dim == 3 ? 2 : 1) < plan.levels; ++n)
      ASSERT_NEAR(plan.length[n], 2 * plan.length[n + (dim == 3 ? 2 : 1)], 1e-9 * plan.length[n]);
  }
}

// The printed rule N = ⌈log2(c/d)⌉ leaves capillaries 4/3 d apart at c/d = 4; the corrected
// rule keeps them within d.
TEST(Lzh, PrintedLevelRuleOvershootsTheSpacingAtPowersOfTwo) {
  LzhParameters p = block(2, 5, 20, 1, 2, 2, 0.5, 0.1);  // c = 4, c/d = 4
  p.printed_level_rule = true;
  const auto printed = planLzh(p);
  EXPECT_EQ(printed.levels_2d, 2);
  EXPECT_NEAR(printed.leaf_spacing, 4.0 / 3.0, 1e-12);
  p.printed_level_rule = false;
  const auto corrected = planLzh(p);
  EXPECT_EQ(corrected.levels_2d, 3);
  EXPECT_LE(corrected.leaf_spacing, 1.0);
}

TEST(Lzh, ImpossibleBlocksNameTheKey) {
  LzhParameters p = block(3, 10, 5, 1, 2, 2, 0.5, 0.1);
  try {
    planLzh(p);
    FAIL() << "a block too low for its vessels was accepted";
  } catch (const LzhError& e) { EXPECT_EQ(e.key, "block_height"); }
  p.height = 20;
  p.capillary_diameter = 0.6;
  p.capillary_wall = 0.2;  // outer 1.0 mm, pitch 9/15 = 0.6 mm
  try {
    planLzh(p);
    FAIL() << "overlapping capillary walls were accepted";
  } catch (const LzhError& e) { EXPECT_EQ(e.key, "capillary_spacing"); }
}

// Flow: Q in at the inlet, Q/K through each capillary, conserved at every junction; pressure
// equal at every capillary's two ends (all paths alike), falling all the way to the outlet.
TEST(Lzh, FlowsAreConservedAndEveryCapillarySeesTheSamePressures) {
  const auto g = test::growFile(example("lsystem_lzh_3d.toml"));
  const VascularTree& t = g.forest.vessels;
  const auto roots = t.roots();
  const double q = t.flow[t.child0[roots.front()]];
  EXPECT_NEAR(q, 0.1 * 1000.0 / 60.0, 1e-12);
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.child0[i] < 0 || t.isRoot(i)) continue;
    const double out = t.flow[t.child0[i]] + (t.child1[i] >= 0 ? t.flow[t.child1[i]] : 0.0);
    EXPECT_NEAR(out, t.flow[i], 1e-12 * q);
  }
  std::set<long long> top, bottom;
  for (std::size_t k = 1; k + 1 < roots.size(); ++k) {
    EXPECT_NEAR(t.flow[roots[k] + 1], q / double(roots.size() - 2), 1e-15);
    top.insert(std::llround(t.pressure[roots[k]] * 1e6));
    bottom.insert(std::llround(t.pressure[roots[k] + 1] * 1e6));
    EXPECT_LT(t.pressure[roots[k] + 1], t.pressure[roots[k]]);
  }
  EXPECT_EQ(top.size(), 1u);
  EXPECT_EQ(bottom.size(), 1u);
  EXPECT_LT(t.pressure[roots.back()], *bottom.begin() * 1e-6);  // the outlet is lowest
}

// A tapered vessel (a round cone) rasterises to its exact volume: the two spheres' outer parts
// and the frustum between their tangent circles.
TEST(Lzh, TaperedVesselsRasteriseToTheirVolume) {
  VolumeGrid g;
  g.dims = {64, 64, 64};
  g.spacing_mm = Vec3(0.1, 0.1, 0.1);
  g.origin_mm = Vec3(0.05, 0.05, 0.05);
  VascularTree t;
  t.addNode(Vec3(1.23, 1.71, 1.37), -1);
  t.addNode(Vec3(4.91, 4.33, 5.02), 0);
  const double ra = 0.45, rb = 0.12;
  t.radius_start[1] = ra;
  t.radius[1] = rb;
  const auto gt = rasterizeGroundTruth(t, g, RasterOptions{});
  double sum = 0;
  for (float v : gt.fraction.data) sum += v;
  sum *= 0.001;
  const double l = distance(t.position[0], t.position[1]), s = (ra - rb) / l, c = std::sqrt(1 - s * s);
  const double pi = std::numbers::pi;
  const auto cap = [&](double r, double h) { return pi * h * h * (3 * r - h) / 3; };
  const double frustum = pi * l * c * c / 3 * (ra * ra * c * c + ra * rb * c * c + rb * rb * c * c);
  const double exact = 4 * pi * ra * ra * ra / 3 - cap(ra, ra - ra * s) + cap(rb, rb - rb * s) + frustum;
  EXPECT_NEAR(sum, exact, 0.005 * exact) << "rasterised " << sum << " mm^3, exact " << exact;
  // The radius channel follows the taper: each centreline voxel holds the radius across from its centre.
  int checked = 0;
  const Vec3 a = t.position[0], ab = t.position[1] - t.position[0];
  for (std::int64_t z = 0; z < g.dims[2]; ++z)
    for (std::int64_t y = 0; y < g.dims[1]; ++y)
      for (std::int64_t x = 0; x < g.dims[0]; ++x) {
        if (!gt.centerline.at(x, y, z)) continue;
        const double f = std::clamp(dot(g.centre(x, y, z) - a, ab) / dot(ab, ab), 0.0, 1.0);
        EXPECT_NEAR(gt.radius.at(x, y, z), ra + f * (rb - ra), 1e-6);
        ++checked;
      }
  EXPECT_GT(checked, 30);
}

// Rasterised unclipped, the closed network is one 6-connected component in the mask and (with
// centerline_connectivity = 6) in the centreline volume, also when its capillaries are thinner
// than a voxel.
TEST(Lzh, TheNetworkIsOneSixConnectedComponent) {
  for (double capillary : {0.2, 0.03}) {
    const LzhParameters p = block(3, 6, 12, 1.1, 2, 1, 0.8, capillary);
    const auto plan = planLzh(p);
    const double voxel = 0.1, m = p.start_diameter / 2 + 2 * voxel;
    const Forest f = buildLzhNetwork(p, plan, Vec3(m, m, m));
    VolumeGrid g;
    g.dims = {std::int32_t(std::ceil((p.block_width + 2 * m) / voxel)), std::int32_t(std::ceil((p.block_width + 2 * m) / voxel)),
              std::int32_t(std::ceil((p.height + 2 * m) / voxel))};
    g.spacing_mm = Vec3(voxel, voxel, voxel);
    g.origin_mm = Vec3(voxel / 2, voxel / 2, voxel / 2);
    const auto gt = rasterizeGroundTruth(f.vessels, g, RasterOptions{4, 6});
    EXPECT_EQ(test::sixConnectedComponents(gt.mask), 1) << "capillary diameter " << capillary << " mm";
    EXPECT_EQ(test::sixConnectedComponents(gt.centerline), 1) << "capillary diameter " << capillary << " mm";
    // The default thin curve (26-connected) is not face-connected: the option is what makes it so.
    EXPECT_GT(test::sixConnectedComponents(rasterizeGroundTruth(f.vessels, g, RasterOptions{}).centerline), 1);
  }
}

// Zamir's optimal angles: equal daughters leave at arccos(2^(-1/3)) = 37.47° each (Murray's
// symmetric angle for k = 3); a thinner daughter turns more than its sibling.
TEST(Grammar, ZamirAnglesMatchMurrayForEqualDaughters) {
  double a, b;
  zamirAngles(1, 1, a, b);
  EXPECT_NEAR(a, std::acos(std::pow(2.0, -1.0 / 3)), 1e-12);  // 37.467°
  EXPECT_NEAR(a, b, 1e-15);
  zamirAngles(1, 0.5, a, b);
  EXPECT_LT(a, b);
}

// The grammar example: Murray's law at every bifurcation, tips where the grammar asks, no
// overlapping vessels, every vessel inside the sphere, the same tree for the same seed on any
// thread count, and one 6-connected component once rasterised.
TEST(Grammar, TreeKeepsMurrayStaysInsideAndDoesNotOverlap) {
  const auto g = test::growFile(example("lsystem_grammar_3d.toml"));
  const VascularTree& t = g.forest.vessels;
  const GrowthDomain& d = *g.prepared->domain();
  int bifurcations = 0;
  double murray = 0;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    EXPECT_GE(d.depth(t.position[i]), t.radius[i] - 1e-12) << "node " << i;
    if (t.child1[i] < 0) continue;
    ++bifurcations;
    const double p = std::pow(2 * t.radius[i], 3), c = std::pow(2 * t.radius[t.child0[i]], 3) + std::pow(2 * t.radius[t.child1[i]], 3);
    murray = std::max(murray, std::abs(p - c) / p);
  }
  EXPECT_GT(bifurcations, 400);
  EXPECT_LE(murray, 1e-12);
  GrowthReport report;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const auto again = test::growFile(example("lsystem_grammar_3d.toml"), 1, &report);
    EXPECT_EQ(again.forest.vessels.position, t.position);
    EXPECT_EQ(again.forest.vessels.radius, t.radius);
  }
  EXPECT_EQ(report.intersecting_pairs, 0);
  const auto other = test::growFile(example("lsystem_grammar_3d.toml"), 2);
  EXPECT_NE(other.forest.vessels.position, t.position);
}

// Without a wall in reach every one of the 2^n tips grows (1 + 5·(2^(n+1) − 1) nodes); in a
// domain too small the run fails with a message instead of returning a near-empty tree.
TEST(Grammar, AskedTipsGrowOrTheRunFails) {
  GrowthDomain big = GrowthDomain::analytic(DomainShape::Sphere, 100, 4, 2);
  GrammarOptions o;
  o.domain = &big;
  o.iterations = 6;
  o.root_diameter = 0.5;
  o.root = big.center() + Vec3(0, 60, 0);
  o.direction = Vec3(0, -1, 0);
  GrammarReport r;
  const VascularTree t = growGrammar(o, r, {});
  EXPECT_EQ(r.tips, 64);
  EXPECT_EQ(t.nodeCount(), 1 + 5 * 127);
  GrowthDomain small = GrowthDomain::analytic(DomainShape::Sphere, 5, 0.1, 2);
  o.domain = &small;
  o.root = small.defaultRoot();
  o.direction = Vec3(0, -1, 0);
  try {
    GrammarReport r2;
    growGrammar(o, r2, {});
    FAIL() << "a tree that cannot fit was returned";
  } catch (const GrowthError& e) { EXPECT_NE(std::string(e.what()).find("tips its 6 iterations ask for"), std::string::npos) << e.what(); }
}

// V-System's grammar trees fall apart into hundreds of pieces once voxelised; ours rasterises as
// one 6-connected component in the mask and the (6-connected) centreline, its thinnest vessels
// (0.004 mm, 1/25 voxel) included.
TEST(Grammar, RasterisedTreeIsOneSixConnectedComponent) {
  const auto g = test::growFile(example("lsystem_grammar_3d.toml"));
  const auto grid = imageGrid(g.prepared->frame(), ImageParameters{});
  const auto gt = rasterizeGroundTruth(g.forest.vessels, grid, RasterOptions{4, 6});
  EXPECT_EQ(test::sixConnectedComponents(gt.mask), 1);
  EXPECT_EQ(test::sixConnectedComponents(gt.centerline), 1);
}
