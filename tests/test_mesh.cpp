// Surface meshes of real grown forests (src/mesh): closed, manifold, consistently oriented, one
// surface per tree, vertices on the vessels' surface, the same mesh on any thread count;
// the files as written and re-read by VTK (tests/check_mesh.py), with the volume against an
// independent Monte Carlo estimate of the union of capsules.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <nlohmann/json.hpp>

#include "io/graph_writers.hpp"
#include "io/mesh_writers.hpp"
#include "mesh/decimate.hpp"
#include "mesh/net_surface.hpp"
#include "mesh/ring_mesh.hpp"
#include "mesh/surface_checks.hpp"
#include "mesh/tube_surface.hpp"
#include "mesh/vessel_surface.hpp"
#include "raster/vessel_capsule.hpp"
#include "grow_file.hpp"
#include "test_support.hpp"
#include "cli_run.hpp"

using namespace angiosynth;

namespace {

std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The artery and vein of cco_artery_vein_3d.toml with 12 terminals each: a forest of two trees
// (under a million triangles: VTK 9.1's vtkFeatureEdges fails on larger meshes).
const test::Grown& forest() {
  static const test::Grown g = [] {
    auto text = readText(test::sourceDir() / "examples/cco_artery_vein_3d.toml");
    text.replace(text.find("terminals = 4000"), 16, "terminals = 12");
    const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "forest.toml") << text;
    return test::growFile(dir / "forest.toml");
  }();
  return g;
}

// The largest |distance| of a vertex from its tree's union of capsules, over its local step.
double largestDistanceOverStep(const VascularTree& t, const SurfaceMesh& m) {
  std::vector<std::vector<Capsule>> caps(t.roots().size());
  for (std::int32_t s = 0; s < t.nodeCount(); ++s)
    if (!t.isRoot(s)) caps[std::size_t(t.tree[s])].push_back(capsuleOf(t, s));
  EXPECT_EQ(m.vertex_step.size(), m.vertices.size());
  std::vector<std::int32_t> tree_of(m.vertices.size(), 0);
  for (std::size_t k = 0; k < m.triangles.size(); ++k)
    for (auto v : m.triangles[k]) tree_of[std::size_t(v)] = m.triangle_tree[k];
  double worst = 0;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    double d = INFINITY;
    for (const auto& c : caps[std::size_t(tree_of[v])]) d = std::min(d, c.depth(m.vertices[v]));
    worst = std::max(worst, std::abs(d) / m.vertex_step[v]);
  }
  return worst;
}

// A mesh of one tree: closed, manifold, consistently oriented, without degenerate triangles,
// one surface of genus 0 (Euler characteristic 2).
MeshTopology expectOneSurfaceOfGenusZero(const SurfaceMesh& m) {
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.misoriented_edges, 0);
  EXPECT_EQ(topo.degenerate_triangles, 0);
  EXPECT_EQ(topo.tree_components, std::vector<std::int64_t>({1}));
  EXPECT_EQ(topo.tree_euler, std::vector<std::int64_t>({2}));
  return topo;
}

// Node p under `parent`, its vessel of radius r.
std::int32_t addVessel(VascularTree& t, const Vec3& p, std::int32_t parent, double r) {
  const auto id = t.addNode(p, parent);
  t.radius[id] = r;
  return id;
}

// A parent vessel from the origin to `fork` and two daughters from it; radii parent, a, b.
VascularTree bifurcation(const Vec3& fork, const Vec3& a, const Vec3& b, const std::array<double, 3>& radii) {
  VascularTree t;
  const auto root = t.addNode({0, 0, 0}, -1), f = t.addNode(fork, root);
  const auto da = t.addNode(a, f), db = t.addNode(b, f);
  t.radius[f] = radii[0], t.radius[da] = radii[1], t.radius[db] = radii[2];
  return t;
}

// mesh.json's own account of a closed surface: no boundary, non-manifold or misoriented edge,
// no degenerate triangle.
void expectClosedInMeshJson(const nlohmann::json& statistics, const std::string& what = {}) {
  for (const char* key : {"boundary_edges", "nonmanifold_edges", "misoriented_edges", "degenerate_triangles"})
    EXPECT_EQ(statistics[key], 0) << key << " " << what;
}

// A tree of vessels of radius 0.5 whose third generation comes back to end at (5, y, 0), beside its
// root vessel (the x axis): walls y − 1 apart.
VascularTree treeComingBackTo(double y) {
  VascularTree t;
  const auto add = [&](const Vec3& p, std::int32_t parent) { return addVessel(t, p, parent, 0.5); };
  const auto root = add({0, 0, 0}, -1), a = add({10, 0, 0}, root);
  const auto b = add({10, 10, 0}, a);
  add({14, -3, 0}, a);
  const auto d = add({5, 10, 0}, b);
  add({14, 13, 0}, b);
  add({5, y, 0}, d);
  add({2, 13, 0}, d);
  return t;
}

// The tube mesher's surface at `samples` across where vessels meet (by surface nets where they
// pass, or by marching tetrahedra only).
SurfaceMesh tubeMesh(const VascularTree& t, int samples, TubeSurfaceReport* rep = nullptr, bool nets = true) {
  TubeSurfaceOptions o;
  o.junction.samples_across = samples;
  o.nets = nets;
  return tubeSurface(t, o, rep);
}

// A directory with the artery and vein of cco_artery_vein_3d.toml grown at `terminals` each
// (`extra` appended to its parameter file) into dir/sample by the command.
std::filesystem::path grownSample(const std::string& name, int terminals, const std::string& extra = "") {
  const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto text = readText(test::sourceDir() / "examples/cco_artery_vein_3d.toml");
  text.replace(text.find("terminals = 4000"), 16, "terminals = " + std::to_string(terminals));
  std::ofstream(dir / "forest.toml") << text << extra;
  const auto grown = run("generate forest.toml --out sample --no-image --quiet", dir);
  EXPECT_EQ(grown.code, 0) << grown.err;
  return dir;
}

}  // namespace

// The tubes: most vessels of the test forest run free and get rings on their walls, the rest is
// contoured; the parts join into one closed, manifold, outward surface of genus 0 per tree, every
// vertex within half its local step of the vessels, several times fewer triangles than the
// contour, and the same mesh on one thread.
TEST(Mesh, TubesJoinContouredJunctionsIntoOneSurfaceOfGenusZeroPerTree) {
  const auto& t = forest().forest.vessels;
  TubeSurfaceReport rep;
  const auto m = tubeMesh(t, 3, &rep);
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.misoriented_edges, 0);
  EXPECT_EQ(topo.degenerate_triangles, 0);
  EXPECT_EQ(topo.tree_components, std::vector<std::int64_t>({1, 1}));
  EXPECT_EQ(topo.tree_euler, std::vector<std::int64_t>({2, 2}));
  EXPECT_GT(rep.tubes * 2, rep.vessels) << "most vessels run free";
  EXPECT_GT(rep.netted * 2, rep.clusters) << "most parts contoured by surface nets";
  EXPECT_GT(rep.tube_triangles, 0);
  EXPECT_EQ(rep.contour_triangles + rep.tube_triangles, std::int64_t(m.triangles.size()));
  EXPECT_LE(largestDistanceOverStep(t, m), 0.5);
  const auto contour = vesselSurface(t, SurfaceOptions{});
  EXPECT_LT(m.triangles.size() * 4, contour.triangles.size());
  EXPECT_NEAR(topo.volume_mm3, meshTopology(contour).volume_mm3, 3e-3 * topo.volume_mm3);
  std::cout << rep.tubes << " tubes of " << rep.vessels << " vessels, " << rep.clusters << " contoured parts, " << m.triangles.size()
            << " triangles (contour " << contour.triangles.size() << "), given up " << rep.fallbacks << ", volume " << topo.volume_mm3 << " mm^3\n";
  // Marching tetrahedra in every part: the same topology and volume, more triangles.
  TubeSurfaceReport tet_rep;
  const auto mt = tubeMesh(t, 3, &tet_rep, false);
  EXPECT_EQ(tet_rep.netted, 0);
  EXPECT_EQ(meshTopology(mt).tree_euler, topo.tree_euler);
  EXPECT_NEAR(meshTopology(mt).volume_mm3, topo.volume_mm3, 1e-3 * topo.volume_mm3);
  EXPECT_LT(rep.contour_triangles, tet_rep.contour_triangles);
  std::cout << rep.netted << " of " << rep.clusters << " parts by surface nets: " << rep.contour_triangles << " contoured triangles against "
            << tet_rep.contour_triangles << " by marching tetrahedra\n";
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const auto m1 = tubeMesh(t, 3);
  EXPECT_EQ(m1.triangles, m.triangles);
  EXPECT_EQ(m1.vertices, m.vertices);
}

// Surface nets on a bifurcation: one closed, manifold, outward surface of genus 0, every vertex
// within a quarter of the step of the vessels' union (the volume restoration moves them), the enclosed volume of marching tetrahedra's
// at the same step within 0.3 %, and under half their triangles. Parts it cannot serve are refused:
// gaps to resolve, and radii so far apart that one step for all costs more than the octree.
TEST(Mesh, SurfaceNetsContourAJunctionClosedOnTheVesselsWithFewerTriangles) {
  const VascularTree t = bifurcation({10, 0, 0}, {18, 4, 0}, {17, -4, 1.5}, {1.0, 0.8, 0.75});
  const std::int32_t fork = 1, left = 2, right = 3;  // bifurcation()'s nodes after the root
  SurfaceOptions o;
  o.samples_across = 3;
  SurfaceReport rep;
  NetReport why;
  const auto net = netSurface(t, o, &rep, &why);
  ASSERT_TRUE(net.has_value()) << why.refused;
  const auto topo = expectOneSurfaceOfGenusZero(*net);
  const double worst = largestDistanceOverStep(t, *net);
  EXPECT_LT(worst, 0.25);
  const auto tet = vesselSurface(t, o);
  const double v_tet = meshTopology(tet).volume_mm3;
  EXPECT_NEAR(topo.volume_mm3, v_tet, 3e-3 * v_tet);
  EXPECT_LT(net->triangles.size() * 2, tet.triangles.size());
  std::cout << net->triangles.size() << " triangles by surface nets, " << tet.triangles.size() << " by marching tetrahedra; volume "
            << topo.volume_mm3 << " against " << v_tet << " mm^3; largest distance / step " << worst << "\n";
  SurfaceOptions gaps = o;
  gaps.vessel_max_cell_mm.assign(std::size_t(t.nodeCount()), 0.0);
  gaps.vessel_max_cell_mm[std::size_t(left)] = 0.05;
  EXPECT_FALSE(netSurface(t, gaps, nullptr, &why).has_value());
  EXPECT_STREQ(why.refused, "gaps to resolve");
  EXPECT_FALSE(why.costlier);
  VascularTree thin = t;
  thin.radius[fork] = 3.0;
  thin.radius[right] = 0.2;
  EXPECT_FALSE(netSurface(thin, o, nullptr, &why).has_value());
  EXPECT_TRUE(why.costlier) << why.refused;
}

// Where radii lie far apart, the nets are made on the octree instead (each vessel at its own
// step; the dual of its leaves): the same checks pass, the triangles are a third of marching
// tetrahedra's on the same cells, the volume theirs within 0.3 %, the mesh the same on one thread.
TEST(Mesh, DualContourOnTheOctreeKeepsEachVesselsStep) {
  const VascularTree t = bifurcation({12, 0, 0}, {24, 3, 0}, {18, -5, 2}, {2.0, 1.8, 0.25});
  SurfaceOptions o;
  o.samples_across = 3;
  o.dual = true;
  SurfaceReport rep;
  const auto dual = vesselSurface(t, o, &rep);
  ASSERT_TRUE(rep.dual) << rep.dual_refused;
  EXPECT_GE(rep.levels, 3);
  const auto topo = expectOneSurfaceOfGenusZero(dual);
  const double worst = largestDistanceOverStep(t, dual);
  EXPECT_LT(worst, 0.25);
  SurfaceOptions tet = o;
  tet.dual = false;
  const auto mt = vesselSurface(t, tet);
  const double v_tet = meshTopology(mt).volume_mm3;
  EXPECT_NEAR(topo.volume_mm3, v_tet, 3e-3 * v_tet);
  EXPECT_LT(dual.triangles.size() * 2, mt.triangles.size());
  std::cout << dual.triangles.size() << " triangles on the octree's dual, " << mt.triangles.size() << " by marching tetrahedra; volume "
            << topo.volume_mm3 << " against " << v_tet << " mm^3; largest distance / step " << worst << "; " << rep.levels << " levels\n";
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const auto d1 = vesselSurface(t, o);
  EXPECT_EQ(d1.triangles, dual.triangles);
  EXPECT_EQ(d1.vertices, dual.vertices);
}

// Where a leaf's sheet crosses a face in two arcs and the leaf across has them in one sheet too,
// one vertex per sheet gives that pair of vertices one edge for both arcs: four triangles on one
// edge, refused as no manifold (and contoured by tetrahedra). A vertex on each arc keeps it a
// closed manifold. The vessels of a part of the 10k benchmark tree (bench/mesh_cco_5000.toml)
// where vessels touch, each segment as its own root as the tube mesher passes them: the net has
// two such pairs, is accepted, and has the tetrahedra's topology and volume with a third of
// their triangles.
TEST(Mesh, DualContourGivesEachArcOfAFaceItsOwnVertex) {
  struct Segment {
    Vec3 a, b;
    double r;
  };
  const Segment segments[] = {
      {{39.2205886, 14.502347, 34.1002379}, {38.3070757, 14.6783801, 33.9982283}, 0.312704154},
      {{40.5378, 14.6062619, 34.2168838}, {40.6608265, 14.9649924, 34.0521948}, 0.094094864},
      {{40.5378, 14.6062619, 34.2168838}, {40.7901333, 14.8513518, 34.4729525}, 0.112796886},
      {{40.9509657, 13.8518584, 34.2576888}, {41.1074387, 13.9224242, 33.8312336}, 0.0558019538},
      {{40.9509657, 13.8518584, 34.2576888}, {41.7561491, 13.4512024, 34.3675317}, 0.301802277},
      {{39.2205886, 14.502347, 34.1002379}, {39.6513517, 14.0096685, 34.3553119}, 0.0864410802},
      {{39.2205886, 14.502347, 34.1002379}, {39.5589339, 14.3981296, 34.1402927}, 0.310486696},
      {{39.5589339, 14.3981296, 34.1402927}, {39.9873379, 14.2661723, 34.1910091}, 0.310486696},
      {{39.9873379, 14.2661723, 34.1910091}, {40.2254261, 14.1928362, 34.219195}, 0.310486696},
      {{39.6513517, 14.0096685, 34.3553119}, {39.6543369, 13.9359417, 34.3531744}, 0.0612980728},
      {{39.6543369, 13.9359417, 34.3531744}, {39.7325531, 12.004206, 34.2971677}, 0.0612980728},
      {{39.6513517, 14.0096685, 34.3553119}, {43.1917393, 12.6395661, 36.6005363}, 0.0746243915},
      {{40.2254261, 14.1928362, 34.219195}, {40.5378, 14.6062619, 34.2168838}, 0.131390044},
      {{40.2254261, 14.1928362, 34.219195}, {40.9509657, 13.8518584, 34.2576888}, 0.302436832},
  };
  VascularTree t;
  for (const auto& s : segments) {
    const auto root = t.addNode(s.a, -1), end = t.addNode(s.b, root);
    t.radius[root] = 0, t.radius[end] = s.r;
  }
  SurfaceOptions o;
  o.samples_across = 3;
  o.dual = true;
  // Vessels 15 and 19 (their end nodes) come close across a gap, resolved as the mesher does.
  o.vessel_max_cell_mm.assign(std::size_t(t.nodeCount()), 0);
  o.vessel_max_cell_mm[15] = o.vessel_max_cell_mm[19] = 0.00721951;
  o.vessel_gap_partners.resize(std::size_t(t.nodeCount()));
  o.vessel_gap_partners[15] = {19};
  o.vessel_gap_partners[19] = {15};
  SurfaceReport rep;
  const auto dual = vesselSurface(t, o, &rep);
  ASSERT_TRUE(rep.dual) << rep.dual_refused;
  const auto topo = meshTopology(dual);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.misoriented_edges, 0);
  EXPECT_EQ(topo.degenerate_triangles, 0);
  // Within half a step of the capsules, as marching tetrahedra's vertices (0.44 here: the fillet
  // rounds the creases where vessels meet).
  EXPECT_LT(largestDistanceOverStep(t, dual), 0.5);
  SurfaceOptions tet = o;
  tet.dual = false;
  const auto mt = vesselSurface(t, tet);
  const auto mt_topo = meshTopology(mt);
  EXPECT_EQ(topo.tree_components, mt_topo.tree_components);
  EXPECT_EQ(topo.tree_euler, mt_topo.tree_euler);
  EXPECT_NEAR(topo.volume_mm3, mt_topo.volume_mm3, 3e-3 * mt_topo.volume_mm3);
  EXPECT_LT(dual.triangles.size() * 2, mt.triangles.size());
  std::cout << dual.triangles.size() << " triangles on the octree's dual, " << mt.triangles.size() << " by marching tetrahedra; volume "
            << topo.volume_mm3 << " against " << mt_topo.volume_mm3 << " mm^3; euler " << topo.tree_euler[0] << "\n";
}

// A lone straight vessel is one tube with round ends. At the capped spacing (1.5 vertex
// spacings) its rings are turned by half a vertex spacing against each other, so every triangle
// along it is acute (on aligned rings they were right-angled, and TetGen splits the long edge of
// each such pair), and the rings' radius and the caps' scale give it the capsule's volume (the
// band between staggered rings is a prismatoid, the divergence theorem counts it exactly). Rings
// radii apart are aligned, and the capsule's volume is as exact with 2 radii between rings as
// with 8 (a band between aligned rings is a frustum of a pyramid), with fewer triangles.
TEST(Mesh, StaggeredRingsMakeAcuteTrianglesAndKeepTheCapsulesVolume) {
  VascularTree t;
  const auto root = t.addNode({0, 0, 0}, -1), leaf = t.addNode({20, 3, 4}, root);
  t.radius[root] = t.radius[leaf] = 0.8;
  const double length = norm(Vec3(20, 3, 4)), exact = std::numbers::pi * 0.64 * length + 4.0 / 3 * std::numbers::pi * 0.512;
  std::vector<std::int64_t> triangles;
  for (const double spacing : {0.0, 2.0, 8.0}) {
    TubeSurfaceOptions o;
    o.junction.samples_across = 3;
    o.ring_spacing_radii = spacing;
    TubeSurfaceReport rep;
    const auto m = tubeSurface(t, o, &rep);
    EXPECT_EQ(rep.tubes, 1);
    const auto topo = meshTopology(m);
    EXPECT_EQ(topo.tree_euler, std::vector<std::int64_t>({2}));
    EXPECT_NEAR(topo.volume_mm3, exact, 1e-3 * exact) << spacing;
    triangles.push_back(rep.tube_triangles);
    if (spacing > 0) continue;
    // Along the tube (away from the round ends' latitude rings), no angle reaches 90°.
    std::int64_t along = 0, right_or_obtuse = 0;
    for (const auto& tri : m.triangles) {
      const Vec3 p[3] = {m.vertices[std::size_t(tri[0])], m.vertices[std::size_t(tri[1])], m.vertices[std::size_t(tri[2])]};
      const double x = dot((p[0] + p[1] + p[2]) / 3.0, Vec3(20, 3, 4)) / length;
      if (x < 1 || x > length - 1) continue;
      ++along;
      for (int i = 0; i < 3; ++i)
        right_or_obtuse += dot(p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]) <= 1e-9 * dot(p[(i + 1) % 3] - p[i], p[(i + 1) % 3] - p[i]);
    }
    EXPECT_GT(along, 40);
    EXPECT_EQ(right_or_obtuse, 0);
  }
  // 25.8 radii long: 13 bands of 2 × 10 triangles at 2 radii, 4 at 8 (the round ends alike).
  EXPECT_GT(triangles[0], triangles[1]);
  EXPECT_EQ(triangles[1] - triangles[2], 2 * 10 * (13 - 4));
}

// Two vessels of a tree that come within a tenth of their radii without touching are contoured
// together; the gap between them stays open (cells of a third of it along the close stretch), so
// the loop the tree closes through them is no handle: one closed surface of genus 0. A U of
// vessels of radius 0.5 whose leaf ends 0.085 mm from the root vessel's wall.
TEST(Mesh, VesselsCloseAcrossAGapStayApartAndTheSurfaceKeepsGenusZero) {
  const auto t = treeComingBackTo(1.085);
  TubeSurfaceReport rep;
  const auto m = tubeMesh(t, 3, &rep);
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.tree_components, std::vector<std::int64_t>({1}));
  EXPECT_EQ(topo.tree_euler, std::vector<std::int64_t>({2}));
  EXPECT_GT(rep.tubes, 0);
  EXPECT_LE(largestDistanceOverStep(t, m), 0.5);
  // No triangle crosses the gap: the point midway between the two walls is outside (ray parity).
  const Vec3 mid(5, 0.5425, 0), dir(0.0123, 0.0071, 1);
  int crossings = 0;
  for (const auto& tri : m.triangles) {
    const Vec3 p0 = m.vertices[std::size_t(tri[0])], e1 = m.vertices[std::size_t(tri[1])] - p0, e2 = m.vertices[std::size_t(tri[2])] - p0;
    const Vec3 h = cross(dir, e2);
    const double det = dot(e1, h);
    if (std::abs(det) < 1e-15) continue;
    const Vec3 s = mid - p0;
    const double u = dot(s, h) / det, v = dot(dir, cross(s, e1)) / det, w = dot(e2, cross(s, e1)) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && w > 0) ++crossings;
  }
  EXPECT_EQ(crossings % 2, 0) << "the gap is filled";
}

// Two vessels of a tree whose walls come a hair apart (a thousandth of their radius: too thin for
// cells to resolve, so they touch): the part that holds them goes by surface nets, whose contour
// may close the contact (a handle) or keep it open (the exact union's shape, whose two sides then
// join through the tubes beyond the part). Either is one closed surface per tree.
TEST(Mesh, VesselsTouchingAcrossAHairAreContouredByNetsClosedOrOpen) {
  const auto t = treeComingBackTo(1.0005);
  TubeSurfaceReport rep;
  const auto m = tubeMesh(t, 3, &rep);
  EXPECT_EQ(rep.netted, rep.clusters);  // the touching part too
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.misoriented_edges, 0);
  EXPECT_EQ(topo.tree_components, std::vector<std::int64_t>({1}));
  EXPECT_TRUE(topo.tree_euler == std::vector<std::int64_t>({2}) || topo.tree_euler == std::vector<std::int64_t>({0})) << topo.tree_euler[0];
  EXPECT_LE(largestDistanceOverStep(t, m), 0.5);
}

// Two vessels joined by a short third one come close only through it: they do not touch, and
// the part that holds them is contoured again until it keeps no handle (found in a forest Clang
// grew when its random draws were unsequenced: one handle before).
// The junctions Clang's tree had, the vessel between n1 and n2 scaled by `connector` (the rest
// moved with n2): below 0.95 the vessels on either side of it overlap, through it.
VascularTree zigzag(double connector) {
  VascularTree t;
  const auto add = [&](const Vec3& p, std::int32_t parent, double r) { return addVessel(t, p, parent, r); };
  const auto root = add({24.4, 57.75, 29.4}, -1, 0);
  const auto n1 = add({23.3181, 54.6138, 28.5927}, root, 0.993377);
  const Vec3 shift = (Vec3(24.3689, 52.8999, 29.0966) - Vec3(23.3181, 54.6138, 28.5927)) * (connector - 1);
  const auto n2 = add(Vec3(24.3689, 52.8999, 29.0966) + shift, n1, 0.973217);
  const auto n3 = add(Vec3(25.7158, 50.7397, 29.5157) + shift, n2, 0.965665);
  const auto n4 = add(Vec3(26.6279, 48.9308, 29.4072) + shift, n3, 0.939007);
  // The side branches, prolonged to 6 mm along their directions.
  const auto branch = [&](std::int32_t from, const Vec3& towards, double r) {
    const Vec3 u = towards - t.position[std::size_t(from)];
    add(t.position[std::size_t(from)] + u / norm(u) * 6.0, from, r);
  };
  branch(n1, {21.8918, 53.7136, 28.0569}, 0.388153);
  branch(n2, Vec3(24.5153, 52.3452, 31.14) + shift, 0.277166);
  branch(n3, Vec3(26.6106, 50.4634, 31.4644) + shift, 0.417047);
  branch(n4, Vec3(25.6497, 46.9178, 30.238) + shift, 0.656128);
  branch(n4, Vec3(28.5636, 47.3164, 28.8893) + shift, 0.817075);
  return t;
}

TEST(Mesh, VesselsJoinedByAShortVesselDoNotTouchAndKeepNoHandle) {
  for (double connector : {1.0, 0.9, 0.8, 0.7, 0.6}) {
    const auto t = zigzag(connector);
    const auto m = tubeMesh(t, 3);
    const auto topo = meshTopology(m);
    EXPECT_EQ(topo.boundary_edges, 0) << connector;
    EXPECT_EQ(topo.nonmanifold_edges, 0) << connector;
    EXPECT_EQ(topo.tree_components, std::vector<std::int64_t>({1})) << connector;
    EXPECT_EQ(topo.tree_euler, std::vector<std::int64_t>({2})) << connector;
  }
}

// A tube whose two ends lie in one contoured part (its sibling at one end overlaps a child at the
// other, so the loop they close is one part): its cuts' regions would each hold the other stub's
// wall, and both cuts fail however far they move. Too short to keep them apart, it is contoured
// whole from the start: one round, no tube given up, and the union's one handle.
TEST(Mesh, ATubeFromAPartBackToItselfTooShortForTwoCutsIsContouredWhole) {
  VascularTree t;
  const auto add = [&](const Vec3& p, std::int32_t parent) { return addVessel(t, p, parent, 0.2); };
  const auto root = add({0, 0, 0}, -1), a = add({5, 0, 0}, root);
  const auto b = add({7, 0, 0}, a);                                                         // the short vessel
  add({5 + 3 * std::cos(std::numbers::pi / 3), 3 * std::sin(std::numbers::pi / 3), 0}, a);  // its sibling, ending at (6.5, 2.6)
  add({6.5, 2.6 - 0.3, 0}, b);                                                              // a child overlapping the sibling's end
  add({10, 0, 0}, b);
  TubeSurfaceReport rep;
  const auto m = tubeMesh(t, 3, &rep);
  EXPECT_EQ(rep.fallbacks, 0);
  EXPECT_EQ(rep.rounds, 1);
  EXPECT_EQ(rep.tubes, 2);  // the trunk and the continuing child
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.misoriented_edges, 0);
  EXPECT_EQ(topo.tree_components, std::vector<std::int64_t>({1}));
  EXPECT_EQ(topo.tree_euler, std::vector<std::int64_t>({0}));  // the loop a → sibling → child → b → a
  EXPECT_LE(largestDistanceOverStep(t, m), 0.5);
}

// A cut loop that steps back by a hair (q a twentieth of a degree behind p) where moving q onto p
// would turn a triangle of q's over, but moving p onto q turns none: the loop is made star-shaped
// by the second collapse (the 100k tree's largest part lost a tube, and was contoured again, for
// want of it). An open tube of radius 1 whose loop lies in z = 0, unrolled as (degrees, z).
TEST(Mesh, ACutLoopSteppingBackIsCollapsedIntoWhicheverEndTurnsNoTriangleOver) {
  SurfaceMesh m;
  const auto at = [&](double deg, double z) {
    const double a = deg * std::numbers::pi / 180;
    m.vertices.push_back({std::cos(a), std::sin(a), z});
    m.vertex_step.push_back(0.5f);
    return std::int32_t(m.vertices.size() - 1);
  };
  std::vector<std::int32_t> L, U;
  for (int k = 0; k < 12; ++k) L.push_back(at(30 * k, 0));
  for (int k = 0; k < 12; ++k) U.push_back(at(15 + 30 * k, 0.6));
  const auto p = L[1], q = at(29.9, 0), w = at(29.95, 0.3), x = at(29.95, 0.6);
  const auto tri = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
    m.triangles.push_back({a, b, c});
    m.triangle_tree.push_back(0);
  };
  for (int k = 0; k < 12; ++k) {
    if (k != 1) tri(L[std::size_t(k)], L[std::size_t((k + 1) % 12)], U[std::size_t(k)]);
    if (k != 1 && k != 2) tri(U[std::size_t((k + 11) % 12)], L[std::size_t(k)], U[std::size_t(k)]);
  }
  tri(p, x, U[0]);
  tri(p, q, x);  // on the edge that steps back: folded
  tri(q, w, x);  // turns over if q moves onto p
  tri(q, L[2], w);
  tri(w, L[2], U[1]);
  tri(w, U[1], x);
  tri(U[1], L[2], U[2]);
  VesselEnd plane;
  plane.centre = {0, 0, 0}, plane.normal = {0, 0, 1}, plane.radius = 1;
  const auto loops = starLoops(m, {plane});
  ASSERT_EQ(loops.size(), 1u);
  ASSERT_EQ(loops[0].size(), 12u);  // p went onto q
  for (std::size_t k = 0; k < 12; ++k) {
    const Vec3 a = m.vertices[std::size_t(loops[0][k])], b = m.vertices[std::size_t(loops[0][(k + 1) % 12])];
    EXPECT_GT(cross(a, b).z, 0) << k;  // rising all the way round
  }
  // No triangle left facing inwards, and the surface still a manifold with one boundary in the plane.
  for (const auto& t : m.triangles) {
    const Vec3 a = m.vertices[std::size_t(t[0])], b = m.vertices[std::size_t(t[1])], c = m.vertices[std::size_t(t[2])];
    const Vec3 centroid = (a + b + c) / 3.0;
    EXPECT_GT(dot(cross(b - a, c - a), Vec3(centroid.x, centroid.y, 0)), 0);
  }
  EXPECT_EQ(meshTopology(m).nonmanifold_edges, 0);
}

// A cut loop whose two neighbouring vertices lie closer than single precision resolves (a cut
// point beside a vertex just off the plane): STL, OFF, PLY and OBJ would round them onto one
// point, leaving a degenerate triangle on each side of the loop (vascusynth_like had 7 such
// pairs, and 3 non-manifold edges in its STL). starLoops takes such an edge out.
TEST(Mesh, CutLoopsKeepNoEdgeThatSinglePrecisionCollapses) {
  // An open tube of radius 0.05 mm at (30, 30) mm, from z = 0 up, closed by a pole; its loop at
  // z = 0 has a 17th vertex 10⁻⁸ mm around the circle from the first.
  const double r = 0.05;
  const Vec3 c(30, 30, 0), u(0, 0, 1);
  SurfaceMesh m;
  const auto ring = [&](double z, int n, bool extra) {
    std::vector<std::int32_t> ids;
    for (int k = 0; k < n; ++k) {
      const double a = 2 * std::numbers::pi * k / n;
      ids.push_back(std::int32_t(m.vertices.size()));
      m.vertices.push_back(c + Vec3(std::cos(a), std::sin(a), 0) * r + u * z);
      if (extra && k == 0) {
        ids.push_back(std::int32_t(m.vertices.size()));
        m.vertices.push_back(c + Vec3(std::cos(1e-8 / r), std::sin(1e-8 / r), 0) * r);
      }
    }
    return ids;
  };
  const auto bottom = ring(0, 16, true), middle = ring(0.1, 16, false), top = ring(0.2, 16, false);
  zipRings(m, c, u, bottom, middle, 0);
  zipRings(m, c, u, middle, top, 0);
  const auto pole = std::int32_t(m.vertices.size());
  m.vertices.push_back(c + u * 0.25);
  for (std::size_t k = 0; k < top.size(); ++k) {
    m.triangles.push_back({top[k], top[(k + 1) % top.size()], pole});
    m.triangle_tree.push_back(0);
    m.triangle_face.push_back(0);
  }
  VesselEnd plane;
  plane.centre = c, plane.normal = u, plane.radius = r;
  const auto rounded = [&](std::int32_t v) {
    const Vec3& p = m.vertices[std::size_t(v)];
    return std::array<float, 3>{float(p.x), float(p.y), float(p.z)};
  };
  ASSERT_EQ(rounded(bottom[0]), rounded(bottom[1]));  // the case: one point in single precision
  const auto loops = starLoops(m, {plane});
  ASSERT_EQ(loops.size(), 1u);
  ASSERT_EQ(loops[0].size(), 16u);
  for (std::size_t k = 0; k < loops[0].size(); ++k) EXPECT_NE(rounded(loops[0][k]), rounded(loops[0][(k + 1) % loops[0].size()])) << k;
  // Every triangle keeps an area with its corners rounded to single precision, and the tube is
  // still a surface with the loop as its one boundary.
  for (const auto& t : m.triangles) {
    const auto a = rounded(t[0]), b = rounded(t[1]), d = rounded(t[2]);
    const Vec3 pa(a[0], a[1], a[2]), pb(b[0], b[1], b[2]), pd(d[0], d[1], d[2]);
    EXPECT_GT(norm(cross(pb - pa, pd - pa)), 0.0);
  }
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 16);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
}

TEST(Mesh, OneClosedOrientedSurfacePerTreeWithItsVerticesOnTheVessels) {
  const auto& t = forest().forest.vessels;
  ASSERT_EQ(t.roots().size(), 2u);
  SurfaceReport rep;
  SurfaceOptions o;
  const auto m = vesselSurface(t, o, &rep);
  ASSERT_GT(m.triangles.size(), 10000u);
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.misoriented_edges, 0);
  EXPECT_EQ(topo.degenerate_triangles, 0);
  EXPECT_GT(topo.volume_mm3, 0);  // outward: the divergence theorem's volume is positive
  // One closed surface per tree, of genus 0: no vessels of these trees overlap, and where two
  // part at a shallow angle the fillet closes the thin gap in one piece (without it, at six
  // samples across, two vessels from one node gave a genus of 1 to 4).
  ASSERT_EQ(topo.tree_components.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(topo.tree_components[k], 1) << "tree " << k;
    EXPECT_EQ(topo.tree_euler[k], 2) << "tree " << k << ": genus 0";
  }
  // Every vertex within half its local step of the union's surface (its tree's capsules): the
  // volume restoration moves vertices by a fraction of the chords' sagitta only.
  const double worst = largestDistanceOverStep(t, m);
  EXPECT_LE(worst, 0.5);
  std::cout << "largest distance from the surface / local step: " << worst << "; largest volume move " << rep.largest_volume_move_mm
            << " mm; finest step " << rep.voxel_mm << " mm\n";
  EXPECT_GT(rep.levels, 1) << "thick vessels sampled coarser than thin ones";
  // The same mesh, bit for bit, on one thread.
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const auto m1 = vesselSurface(t, o);
  EXPECT_EQ(m1.triangles, m.triangles);
  EXPECT_EQ(m1.vertices, m.vertices);
}

// Every format as written, re-read by VTK: closed, manifold, no duplicate or degenerate face, one
// region per tree, outward, and the volume of the union of capsules (Monte Carlo) within 0.5 %.
TEST(Mesh, WrittenFilesReadBackClosedByVtkWithTheUnionsVolume) {
  for (const bool tubes : {false, true}) {
    SCOPED_TRACE(tubes ? "tubes" : "contour");
    const auto& g = forest();
    const auto& t = g.forest.vessels;
    const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_files_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto m = tubes ? tubeMesh(t, 3) : vesselSurface(t, SurfaceOptions{});
    for (const char* f : {"stl", "obj", "ply", "off", "vtp", "3mf"}) {
      std::ofstream out(dir / (std::string("surface.") + f), std::ios::binary);
      meshWriter(f)(out, m);
    }
    {
      std::ofstream n(dir / "nodes.csv"), e(dir / "edges.csv");
      writeNodesCsv(n, t, g.forest.trees);
      writeEdgesCsv(e, t, g.forest.trees);
    }
    const double volume = meshTopology(m).volume_mm3;
    const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' '" + dir.string() + "' '" +
                            (dir / "nodes.csv").string() + "' '" + (dir / "edges.csv").string() + "' > '" + (dir / "check.json").string() + "'";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const auto j = nlohmann::json::parse(readText(dir / "check.json"));
    const double mc = j["union_volume_monte_carlo"];
    std::cout << "mesh volume " << volume << " mm^3, Monte Carlo union " << mc << " mm^3\n";
    EXPECT_LT(std::abs(volume - mc) / mc, 0.005);
    EXPECT_EQ(j["formats"].size(), 6u);
    for (const auto& [ext, f] : j["formats"].items()) {
      EXPECT_EQ(f["points"], m.vertices.size()) << ext << ": vertices welded as written";
      EXPECT_EQ(f["triangles"], m.triangles.size()) << ext;
      EXPECT_EQ(f["boundary_edges"], 0) << ext;
      EXPECT_EQ(f["nonmanifold_edges"], 0) << ext;
      EXPECT_EQ(f["duplicate_faces"], 0) << ext;
      EXPECT_EQ(f["degenerate_faces"], 0) << ext;
      // STL holds single precision, and so do VTK's OBJ, OFF and PLY readers and the 3MF reader's
      // points (about 1e-7 of the volume here, 1e-5 allowed); VTP is read in double.
      EXPECT_NEAR(f["volume"].get<double>() / volume, 1, ext == "vtp" ? 1e-9 : 1e-5) << ext;
      ASSERT_EQ(f["regions"].size(), 2u) << ext << ": one closed surface per tree";
      for (const auto& r : f["regions"]) EXPECT_GT(r["signed_volume"], 0) << ext << ": outward";
    }
    std::filesystem::remove_all(dir);
  }
}

// TetGen's exact face-pair test (tetgen -d, Debian) on every format as VTK re-reads it: no two
// faces intersect, after the volume restoration moved the vertices and after single-precision
// STL rounded them. A coarser mesh of the same forest (two samples across, three levels of
// cells) keeps TetGen's run short.
TEST(Mesh, TetgenFindsNoSelfIntersectionInAnyFormat) {
  for (const bool tubes : {false, true}) {
    SCOPED_TRACE(tubes ? "tubes" : "contour");
    const auto& t = forest().forest.vessels;
    const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_tetgen_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    SurfaceOptions o;
    o.samples_across = 2;
    SurfaceReport rep;
    const auto m = tubes ? tubeMesh(t, 2) : vesselSurface(t, o, &rep);
    if (!tubes) {
      EXPECT_GE(rep.levels, 3);
      EXPECT_GT(rep.largest_volume_move_mm, 0);
    }
    for (const char* f : {"stl", "obj", "ply", "off", "vtp", "3mf"}) {
      std::ofstream out(dir / (std::string("surface.") + f), std::ios::binary);
      meshWriter(f)(out, m);
    }
    const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --self-intersections '" + dir.string() +
                            "' stl obj ply off vtp 3mf > '" + (dir / "tetgen.json").string() + "'";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const auto j = nlohmann::json::parse(readText(dir / "tetgen.json"));
    ASSERT_EQ(j.size(), 6u);
    for (const auto& [ext, pairs] : j.items()) EXPECT_EQ(pairs, 0) << ext << ": intersecting face pairs";
    std::cout << m.triangles.size() << " triangles, " << j.dump() << "\n";
    std::filesystem::remove_all(dir);
  }
}

// `angiosynth mesh` end to end: a sample directory in, the surface and mesh.json out; a missing
// input and a surface beyond the memory limit are refused (exit 2) with nothing written.
TEST(Mesh, CommandWritesTheSurfaceAndRefusesWhatItCannotDo) {
  const auto dir = grownSample("cli", 6);
  const auto ok = run("mesh sample --out surface --format stl,ply --quiet", dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  const auto j = nlohmann::json::parse(readText(dir / "surface/mesh.json"));
  EXPECT_EQ(j["statistics"]["trees"], 2);
  EXPECT_EQ(j["statistics"]["boundary_edges"], 0);
  EXPECT_EQ(j["statistics"]["tree_components"], nlohmann::json::array({1, 1}));
  EXPECT_TRUE(std::filesystem::exists(dir / "surface/surface.stl"));
  EXPECT_TRUE(std::filesystem::exists(dir / "surface/surface.ply"));
  const auto missing = run("mesh nowhere --quiet", dir);
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("nowhere: no such sample directory or graph file"), std::string::npos) << missing.err;
  const auto big = run("mesh sample --out big --voxel 0.0005 --memory-limit 0.01 --quiet", dir);
  EXPECT_EQ(big.code, 2);
  EXPECT_NE(big.err.find("more than the limit"), std::string::npos) << big.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "big"));
  std::filesystem::remove_all(dir);
}

// A flow extension is added geometry: in this 40-terminal disc, unchecked, two outlets' extensions
// ran into other vessels and fused with them (a capped surface of Euler characteristic -2, two
// handles). Each is now shortened, named in a warning and in surface_faces.csv, and the tree keeps
// the topology of its graph. A surface that does not (a graph whose walls overlap) is named with
// the vessels that cause it.
TEST(Mesh, FlowExtensionsStopShortOfOtherVesselsAndTheTopologyIsChecked) {
  const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_extension_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto text = readText(test::sourceDir() / "examples/cco_disc_2d.toml");
  text.replace(text.find("terminals = 4000"), 16, "terminals = 40");
  std::ofstream(dir / "disc.toml") << text;
  ASSERT_EQ(run("generate disc.toml --seed 3 --out sample --no-image --quiet", dir).code, 0);
  const auto capped = run("mesh sample --out capped --ends capped --flow-extension 5 --quiet", dir);
  ASSERT_EQ(capped.code, 0) << capped.err;
  const auto st = nlohmann::json::parse(readText(dir / "capped/mesh.json"))["statistics"];
  EXPECT_EQ(st["tree_euler_characteristic"], nlohmann::json::array({2}));
  EXPECT_EQ(st["tree_euler_expected"], nlohmann::json::array({2}));
  EXPECT_EQ(st["boundary_edges"], 0);
  const auto shortened = st["ends_extension_shortened"].get<int>();
  EXPECT_GE(shortened, 1);
  EXPECT_EQ(st["warnings"].size(), std::size_t(shortened + st["ends_left_closed"].get<int>()));
  EXPECT_NE(capped.err.find("flow extension shortened to"), std::string::npos) << capped.err;
  // surface_faces.csv: the extension each end got, 5 radii or less where it was shortened.
  std::istringstream rows(readText(dir / "capped/surface_faces.csv"));
  std::string row;
  std::getline(rows, row);
  EXPECT_EQ(row.substr(row.rfind(',') + 1), "extension_radii");
  int short_rows = 0;
  while (std::getline(rows, row)) {
    const auto last = row.substr(row.rfind(',') + 1);
    if (last.empty()) continue;  // the wall
    EXPECT_LE(std::stod(last), 5.0);
    short_rows += std::stod(last) < 5;
  }
  EXPECT_EQ(short_rows, shortened);
  // A ring of four vessels whose last ends against the first: one handle, named with its vessels.
  std::ofstream(dir / "ring.swc") << "1 1 0 0 0 1 -1\n2 3 0 10 0 1 1\n3 3 10 10 0 1 2\n4 3 10 0 0 1 3\n5 3 1.5 0 0 1 4\n";
  const auto ring = run("mesh ring.swc --out ring --quiet", dir);
  ASSERT_EQ(ring.code, 0) << ring.err;
  const auto rs = nlohmann::json::parse(readText(dir / "ring/mesh.json"))["statistics"];
  EXPECT_EQ(rs["tree_euler_characteristic"], nlohmann::json::array({0}));
  EXPECT_EQ(rs["tree_euler_expected"], nlohmann::json::array({2}));
  EXPECT_NE(ring.err.find("tree 0: the surface has Euler characteristic 0 in 1 piece, not 2"), std::string::npos) << ring.err;
  EXPECT_NE(ring.err.find("1 handle where vessels fuse (walls within a contour step of each other: vessel 2 and vessel 5)"), std::string::npos)
      << ring.err;
  std::filesystem::remove_all(dir);
}

// [mesh] in a parameter file: generate writes the surface beside the graphs, describes it in
// sample.json, gives the same surface as `angiosynth mesh` on the written graph, and refuses
// a bad value with its line, writing nothing.
TEST(Mesh, MeshTableInAParameterFileWritesTheSurfaceWithTheSample) {
  const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_table_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto text = readText(test::sourceDir() / "examples/cco_artery_vein_3d.toml");
  text.replace(text.find("terminals = 4000"), 16, "terminals = 6");
  std::ofstream(dir / "with_mesh.toml") << text << "\n[mesh]\nformats = [\"stl\", \"off\"]\nsamples_across = 3\nends = \"capped\"\n";
  const auto ok = run("generate with_mesh.toml --out sample --no-image --quiet", dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  const auto j = nlohmann::json::parse(readText(dir / "sample/sample.json"));
  EXPECT_EQ(j["files"]["surface_stl"], "surface.stl");
  EXPECT_EQ(j["files"]["surface_off"], "surface.off");
  EXPECT_EQ(j["parameters"]["mesh"]["samples_across"], 3);
  const auto& st = j["statistics"]["surface"];
  EXPECT_EQ(st["trees"], 2);
  EXPECT_EQ(st["boundary_edges"], 0);
  EXPECT_EQ(st["nonmanifold_edges"], 0);
  EXPECT_EQ(st["tree_components"], nlohmann::json::array({1, 1}));
  // The command on the sample's own graph files gives the same surface, byte for byte.
  ASSERT_EQ(run("mesh sample --out again --format off --samples-across 3 --ends capped --quiet", dir).code, 0);
  EXPECT_TRUE(readText(dir / "again/surface.off") == readText(dir / "sample/surface.off"));  // (no diff of megabytes on failure)
  // The sample knows its vein: blood leaves the venous tree at its root.
  const auto faces = readText(dir / "sample/surface_faces.csv");
  std::istringstream rows(faces);
  std::map<std::string, std::string> root_kind;  // per tree
  for (std::string row; std::getline(rows, row);) {
    std::vector<std::string> field;
    std::istringstream cells(row);
    for (std::string f; std::getline(cells, f, ',');) field.push_back(f);
    if (field.size() > 4 && field[4] == "root") root_kind[field[2]] = field[1];
  }
  EXPECT_EQ(root_kind["0"], "inlet") << faces;
  EXPECT_EQ(root_kind["1"], "outlet") << faces;
  EXPECT_EQ(j["files"]["surface_faces"], "surface_faces.csv");
  // A bad value: exit 2 with the file, its line and the message, and no output.
  const auto refused = [&](const std::string& name, const std::string& mesh_table, const std::string& message) {
    std::ofstream(dir / (name + ".toml")) << text << "\n[mesh]\n" << mesh_table;
    const auto r = run("generate " + name + ".toml --out " + name + " --no-image --quiet", dir);
    EXPECT_EQ(r.code, 2) << name;
    EXPECT_NE(r.err.find(name + ".toml:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / name)) << name;
  };
  refused("bad3", "ends = \"round\"\n", "ends 'round' is not allowed; allowed: closed, open, capped");
  refused("bad4", "wall_ratio = 0.2\nends = \"capped\"\n", "a hollow wall keeps its ends open");
  refused("bad5", "ends = \"capped\"\nclip_box = [0, 0, 0, 10, 10]\n", "clip_box must be an array of 6 numbers");
  refused("bad", "samples_across = 0\n", "samples_across = 0 is out of range; allowed: [1, 64]");
  refused("bad2", "formats = [\"amf\"]\n", "formats 'amf' is not allowed; allowed: stl, obj, ply, off, vtp, 3mf");
  // A clip box from the file: the same surface as the command's --clip-box.
  std::ofstream(dir / "with_box.toml")
      << text << "\n[mesh]\nformats = [\"off\"]\nsamples_across = 3\nends = \"capped\"\nclip_box = [20, 20, 20, 40, 40, 40]\n";
  ASSERT_EQ(run("generate with_box.toml --out boxed --no-image --quiet", dir).code, 0);
  const auto boxed = nlohmann::json::parse(readText(dir / "boxed/sample.json"))["statistics"]["surface"];
  EXPECT_GT(boxed["clip_box_removed_triangles"].get<int>(), 0);
  EXPECT_EQ(boxed["boundary_edges"], 0);
  ASSERT_EQ(run("mesh boxed --out boxed_again --format off --samples-across 3 --ends capped --clip-box 20,20,20,40,40,40 --quiet", dir).code, 0);
  EXPECT_TRUE(readText(dir / "boxed_again/surface.off") == readText(dir / "boxed/surface.off"));
  std::filesystem::remove_all(dir);
}

// CFD ends: each tree's inlet and every outlet cut by the plane through its end node after a
// flow extension, judged by VTK on the written VTP against surface_faces.csv: capped, every cap
// lies in its plane, covers πr² but for a polygon inscribed in the vessel's circle, and faces
// outwards, the surface is closed with one sphere-like component per tree, and TetGen finds no
// intersecting faces; open, there is exactly one planar boundary loop per end and each tree's
// Euler characteristic is the capped one less its ends (each cap a disc).
TEST(Mesh, CappedAndOpenEndsArePlanarLabelledAndWatertight) {
  const auto dir = grownSample("ends", 12);
  const auto check = [&](const std::string& sub, const char* mode) {
    const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' " + mode + " '" + (dir / sub).string() +
                            "'" + (std::string(mode) == "--ends" ? "" : " vtp off") + " > '" + (dir / (sub + ".json")).string() + "'";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    return nlohmann::json::parse(readText(dir / (sub + ".json")));
  };

  // Both methods: the tubes' ends are rings of their own, the contour's cut from it.
  nlohmann::json st, caps;
  for (const std::string method : {"contour", "tubes"}) {
    const auto capped = run(
        "mesh sample --out capped --format vtp,off --ends capped --flow-extension 3 --samples-across 2 --method " + method + " --force --quiet", dir);
    ASSERT_EQ(capped.code, 0) << capped.err;
    st = nlohmann::json::parse(readText(dir / "capped/mesh.json"))["statistics"];
    EXPECT_EQ(st["ends"], 26) << method;  // per tree: its root and 12 leaves
    EXPECT_EQ(st["ends_cut"], 26) << method;
    expectClosedInMeshJson(st, method);
    EXPECT_EQ(st["tree_components"], nlohmann::json::array({1, 1})) << method;
    EXPECT_EQ(st["tree_euler_characteristic"], nlohmann::json::array({2, 2})) << method;
    caps = check("capped", "--ends");
    EXPECT_EQ(caps["caps"], 26) << method;
    EXPECT_EQ(caps["boundary_loops"], 0) << method;
    EXPECT_LT(caps["max_cap_plane_distance"].get<double>(), 1e-9) << method;  // share of the radius
    EXPECT_GT(caps["min_cap_area_ratio"].get<double>(), 0.95) << method;      // at two samples across a loop can have 12 vertices (0.955 πr²)
    // (the contour's loop runs through vertices the volume restoration moved out and the repair
    // moved along: at two samples across, up to 1.4 % over)
    EXPECT_LT(caps["max_cap_area_ratio"].get<double>(), 1.02) << method;
    EXPECT_GT(caps["min_cap_normal_cosine"].get<double>(), 0.999999) << method;
    const auto tetgen = check("capped", "--self-intersections");
    for (const auto& [ext, pairs] : tetgen.items()) EXPECT_EQ(pairs, 0) << method << ", " << ext << ": intersecting face pairs";
    const auto faces = readText(dir / "capped/surface_faces.csv");
    EXPECT_EQ(
        faces.substr(0, faces.find('\n')),
        "face_id,kind,tree,vessel,end,state,centre_x,centre_y,centre_z,normal_x,normal_y,normal_z,radius,cap_area,loop_vertices,extension_radii");
  }
  // Capped, the contour's slivers are repaired by default, and TetGen meshes the volume with
  // quality (radius–edge ratio 1.414) at its default tolerance, undecimated.
  EXPECT_GT(st["sliver_repair_changes"].get<int>(), 100);
  const std::string tetgen_fine = "cd '" + (dir / "capped").string() + "' && tetgen -pq1.414 -Q surface.off > tetgen.log 2>&1";
  EXPECT_EQ(std::system(tetgen_fine.c_str()), 0) << readText(dir / "capped/tetgen.log");
  EXPECT_TRUE(std::filesystem::exists(dir / "capped/surface.1.ele"));
  // Capped, the contoured parts are remeshed by default: TetGen's quality refinement splits
  // fewer of the input triangles than of the nets as they are (--remesh 0), each split costing
  // it a traversal of its queues. Its boundary faces (surface.1.face) per input triangle.
  EXPECT_GT(st["remesh_splits"].get<int>(), 0);
  const auto plain =
      run("mesh sample --out plain --format off --ends capped --flow-extension 3 --samples-across 2 --method tubes --remesh 0 --quiet", dir);
  ASSERT_EQ(plain.code, 0) << plain.err;
  const auto sp = nlohmann::json::parse(readText(dir / "plain/mesh.json"))["statistics"];
  EXPECT_EQ(sp["remesh_changes"], 0);
  const std::string tetgen_plain = "cd '" + (dir / "plain").string() + "' && tetgen -pq1.414 -Q surface.off > tetgen.log 2>&1";
  EXPECT_EQ(std::system(tetgen_plain.c_str()), 0) << readText(dir / "plain/tetgen.log");
  const auto facesPerTriangle = [&](const std::string& sub, const nlohmann::json& stats) {
    std::istringstream face(readText(dir / sub / "surface.1.face"));
    double n = 0;
    face >> n;
    return n / stats["triangles"].get<double>();
  };
  const double remeshed_split = facesPerTriangle("capped", st), plain_split = facesPerTriangle("plain", sp);
  EXPECT_GT(remeshed_split, 1);
  EXPECT_LT(remeshed_split, 0.85 * plain_split) << remeshed_split << " vs " << plain_split << " boundary faces per input triangle";
  for (const char* bad : {"--sliver-angle 40", "--sliver-angle -1", "--max-angle 60", "--max-angle 180"}) {
    const auto refused = run(std::string("mesh sample --out bad --ends capped ") + bad + " --quiet", dir);
    EXPECT_EQ(refused.code, 2) << bad;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad")) << bad;
  }

  const auto open = run("mesh sample --out open --format vtp --ends open --flow-extension 3 --samples-across 2 --quiet", dir);
  ASSERT_EQ(open.code, 0) << open.err;
  const auto so = nlohmann::json::parse(readText(dir / "open/mesh.json"))["statistics"];
  EXPECT_EQ(so["nonmanifold_edges"], 0);
  EXPECT_EQ(so["tree_euler_characteristic"], nlohmann::json::array({2 - 13, 2 - 13}));
  const auto loops = check("open", "--ends");
  EXPECT_EQ(loops["boundary_loops"], 26);
  EXPECT_LT(loops["max_loop_plane_distance"].get<double>(), 1e-9);

  // Decimated, the caps (fixed) and the closedness stay, and TetGen meshes the volume with
  // quality (radius–edge ratio 1.414; -T1e-16: TetGen's default tolerance merges the nearly
  // coplanar neighbours of flat decimated patches into one facet and gives up).
  const auto coarse = run("mesh sample --out coarse --format vtp,off --ends capped --flow-extension 3 --samples-across 2 --decimate --quiet", dir);
  ASSERT_EQ(coarse.code, 0) << coarse.err;
  const auto sc = nlohmann::json::parse(readText(dir / "coarse/mesh.json"))["statistics"];
  EXPECT_EQ(sc["boundary_edges"], 0);
  EXPECT_EQ(sc["nonmanifold_edges"], 0);
  EXPECT_EQ(sc["tree_euler_characteristic"], nlohmann::json::array({2, 2}));
  // The tubes are economical already (capped, their rings 1.5 vertex spacings apart), and the
  // sliver repair's short-edge collapses thin the contour: decimation halves the contoured parts
  // (of the surface not remeshed: decimation does not remesh).
  EXPECT_EQ(sc["remesh_changes"], 0);
  EXPECT_LT(sc["contoured_triangles"].get<double>() * 2, sp["contoured_triangles"].get<double>());
  EXPECT_LT(sc["triangles"].get<double>(), 0.8 * sp["triangles"].get<double>());
  const auto coarse_caps = check("coarse", "--ends");
  EXPECT_EQ(coarse_caps["caps"], 26);
  EXPECT_LT(coarse_caps["max_cap_plane_distance"].get<double>(), 1e-9);
  EXPECT_EQ(coarse_caps["min_cap_area_ratio"], caps["min_cap_area_ratio"]);
  const std::string tetgen_q = "cd '" + (dir / "coarse").string() + "' && tetgen -pq1.414 -T1e-16 -Q surface.off > tetgen.log 2>&1";
  EXPECT_EQ(std::system(tetgen_q.c_str()), 0) << tetgen_q;
  EXPECT_TRUE(std::filesystem::exists(dir / "coarse/surface.1.ele"));

  const auto bad = run("mesh sample --out bad --flow-extension 2 --quiet", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("flow_extension needs open or capped ends"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
  std::filesystem::remove_all(dir);
}

// Hollow walls (Lázaro 2011): a constant wall of 0.1 mm around the test forest's vessels, every end
// open. The surface is closed, manifold and outward, and each tree's has genus k − 1 for its k
// open ends (an end whose vessel ends against another stays closed and is not counted); judged
// on the written file by an independent Monte Carlo of the wall (thickened capsules cut by the
// ends' planes, outside every vessel) and VTK's distance from the outer side to the lumen side:
// the volume within 1 %, the thickness within 5 % at the 95th percentile. A wall of half the
// radius (fewer triangles, for TetGen's run) has no intersecting faces.
TEST(Mesh, HollowWallIsClosedOfGenusEndsLessOneWithItsThicknessAndVolume) {
  const auto dir = grownSample("wall", 12);
  const auto made = run("mesh sample --out wall --format vtp,off --wall-thickness 0.1 --quiet", dir);
  ASSERT_EQ(made.code, 0) << made.err;
  const auto st = nlohmann::json::parse(readText(dir / "wall/mesh.json"))["statistics"];
  expectClosedInMeshJson(st);
  EXPECT_EQ(st["tree_components"], nlohmann::json::array({1, 1}));
  // Open ends per tree from surface_faces.csv.
  std::vector<int> open(2, 0);
  std::istringstream rows(readText(dir / "wall/surface_faces.csv"));
  std::string row;
  std::getline(rows, row);
  std::getline(rows, row);  // the wall
  while (std::getline(rows, row)) {
    std::vector<std::string> f;
    std::istringstream cells(row);
    for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
    ASSERT_GT(f.size(), 13u);
    open[std::size_t(std::stoi(f[2]))] += f[5] == "open";
    // An open end's face is the flat ring from the outer side in to the lumen (its triangles
    // labelled with the end's face id): the annulus of the wall's thickness around the radius.
    if (f[5] != "open") continue;
    const double r = std::stod(f[12]), ring = std::numbers::pi * ((r + 0.1) * (r + 0.1) - r * r);
    EXPECT_NEAR(std::stod(f[13]) / ring, 1.0, 0.05) << row;
  }
  EXPECT_GE(open[0] + open[1], 24) << "at most two of the 26 ends stay closed";
  for (int k = 0; k < 2; ++k) EXPECT_EQ(st["tree_euler_characteristic"][std::size_t(k)], 2 - 2 * (open[std::size_t(k)] - 1)) << "tree " << k;
  const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --wall '" + (dir / "wall").string() +
                          "' '" + (dir / "sample/nodes.csv").string() + "' '" + (dir / "sample/edges.csv").string() + "' 0.1 > '" +
                          (dir / "wall.json").string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const auto j = nlohmann::json::parse(readText(dir / "wall.json"));
  const double mc = j["wall_volume_monte_carlo"], volume = j["mesh_volume"];
  EXPECT_LT(std::abs(volume - mc) / mc, 0.01);
  EXPECT_LT(j["thickness_deviation_p95"].get<double>(), 0.05);
  EXPECT_GT(j["outer_vertices"].get<double>(), 10000);
  std::cout << j.dump() << "\n";
  const auto thick = run("mesh sample --out thick --format off --wall-ratio 0.5 --quiet", dir);
  ASSERT_EQ(thick.code, 0) << thick.err;
  const std::string tetgen = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --self-intersections '" +
                             (dir / "thick").string() + "' off > '" + (dir / "tetgen.json").string() + "'";
  ASSERT_EQ(std::system(tetgen.c_str()), 0) << tetgen;
  EXPECT_EQ(nlohmann::json::parse(readText(dir / "tetgen.json"))["off"], 0) << "intersecting face pairs";
  // A wall needs open ends and the tubes; one kind of thickness at a time.
  for (const char* bad : {"--wall-ratio 0.2 --ends capped", "--wall-ratio 0.2 --wall-thickness 0.1", "--wall-ratio 0.2 --method contour"}) {
    const auto refused = run(std::string("mesh sample --out bad ") + bad + " --quiet", dir);
    EXPECT_EQ(refused.code, 2) << bad;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad")) << bad;
  }
  std::filesystem::remove_all(dir);
}

// Seed 004's printed block: the hollow wall clipped to a box that cuts vessels on all six sides.
// The surface stays closed, manifold and outward; every vertex lies in the box; each side's
// section is filled around open lumens (an outer and a lumen loop at least); the ends outside
// the box are marked so; the wall's volume matches an independent Monte Carlo of the wall
// inside the box (VTK re-reading the VTP), its thickness too; each surface has genus k - 1 for
// its k lumen openings; and TetGen finds no intersecting faces in the STL.
TEST(Mesh, HollowWallClippedToABoxStaysClosedWithOpenLumensAndTheWallsVolume) {
  const auto dir = grownSample("wallbox", 12);
  const std::string box = "10,10,10,40,45,40";
  const auto made = run("mesh sample --out box --format vtp,off,stl --wall-thickness 0.1 --clip-box " + box + " --quiet", dir);
  ASSERT_EQ(made.code, 0) << made.err;
  const auto st = nlohmann::json::parse(readText(dir / "box/mesh.json"))["statistics"];
  expectClosedInMeshJson(st);
  for (int side = 0; side < 6; ++side) {
    EXPECT_GT(st["clip_box_section_area_mm2"][std::size_t(side)].get<double>(), 0) << "side " << side;
    EXPECT_GE(st["clip_box_section_loops"][std::size_t(side)].get<int>(), 2) << "side " << side;
  }
  // Every vertex in the box, and on each side some exactly on its plane.
  std::ifstream off(dir / "box/surface.off");
  std::string magic;
  std::size_t nv = 0, nf = 0, ne = 0;
  off >> magic >> nv >> nf >> ne;
  const double lo[3] = {10, 10, 10}, hi[3] = {40, 45, 40};
  int outside = 0, on_side[6] = {0, 0, 0, 0, 0, 0};
  for (std::size_t v = 0; v < nv; ++v) {
    double x[3];
    off >> x[0] >> x[1] >> x[2];
    for (int k = 0; k < 3; ++k) {
      outside += x[k] < lo[k] || x[k] > hi[k];
      on_side[2 * k] += x[k] == lo[k];
      on_side[2 * k + 1] += x[k] == hi[k];
    }
  }
  EXPECT_EQ(outside, 0);
  for (int side = 0; side < 6; ++side) EXPECT_GT(on_side[side], 10) << "side " << side;
  const auto faces = readText(dir / "box/surface_faces.csv");
  EXPECT_NE(faces.find(",outside_box,"), std::string::npos);
  EXPECT_NE(faces.find(",box,,,+z,section,"), std::string::npos);
  const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --wall '" + (dir / "box").string() +
                          "' '" + (dir / "sample/nodes.csv").string() + "' '" + (dir / "sample/edges.csv").string() + "' 0.1 " + box + " > '" +
                          (dir / "box.json").string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const auto j = nlohmann::json::parse(readText(dir / "box.json"));
  const double mc = j["wall_volume_monte_carlo"], volume = j["mesh_volume"];
  EXPECT_LT(std::abs(volume - mc) / mc, 0.01) << volume << " against " << mc;
  EXPECT_LT(j["thickness_deviation_p95"].get<double>(), 0.05);
  // Each closed surface with k lumen openings (VTK's count: open end rings and the sections'
  // holes) has genus k - 1: the Euler characteristics sum to 4 C - 2 K over C surfaces.
  int components = 0, euler = 0;
  for (const auto& c : st["tree_components"]) components += c.get<int>();
  for (const auto& x : st["tree_euler_characteristic"]) euler += x.get<int>();
  EXPECT_GT(j["section_holes"].get<int>(), 6);
  EXPECT_EQ(euler, 4 * components - 2 * j["lumen_openings"].get<int>());
  std::cout << j.dump() << "\n";
  // TetGen's exact test on the single-precision STL as VTK reads it (cut slivers would turn over).
  const std::string tetgen = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --self-intersections '" +
                             (dir / "box").string() + "' stl > '" + (dir / "tetgen.json").string() + "'";
  ASSERT_EQ(std::system(tetgen.c_str()), 0) << tetgen;
  EXPECT_EQ(nlohmann::json::parse(readText(dir / "tetgen.json"))["stl"], 0) << "intersecting face pairs";
  // A box needs a closed surface, and a lower corner below the upper one.
  for (const char* bad : {"--ends open --clip-box 10,10,10,40,45,40", "--wall-thickness 0.1 --clip-box 10,10,10,40,5,40"}) {
    const auto refused = run(std::string("mesh sample --out bad ") + bad + " --quiet", dir);
    EXPECT_EQ(refused.code, 2) << bad;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad")) << bad;
  }
  std::filesystem::remove_all(dir);
}

// The test forest contoured whole, and again with `finish` applied to the contour; a change of
// its triangles keeps the topology (components and Euler characteristic per tree), closed,
// manifold and outward.
struct Finished {
  SurfaceMesh fine, m;
  MeshTopology before, topo;
};
Finished contouredWith(const std::function<void(SurfaceMesh&, const std::function<double(std::int32_t, const Vec3&)>&)>& finish) {
  const auto& t = forest().forest.vessels;
  SurfaceOptions o;
  Finished f;
  f.fine = vesselSurface(t, o);
  f.before = meshTopology(f.fine);
  o.finish = finish;
  f.m = vesselSurface(t, o);
  f.topo = meshTopology(f.m);
  EXPECT_EQ(f.topo.boundary_edges, 0);
  EXPECT_EQ(f.topo.nonmanifold_edges, 0);
  EXPECT_EQ(f.topo.misoriented_edges, 0);
  EXPECT_EQ(f.topo.degenerate_triangles, 0);
  EXPECT_EQ(f.topo.tree_components, f.before.tree_components);
  EXPECT_EQ(f.topo.tree_euler, f.before.tree_euler);
  return f;
}

// Decimation keeps what the marching-tetrahedra surface guarantees and changes its triangles
// only: the same components and Euler characteristics per tree (the link condition), closed,
// manifold and outward, the enclosed volume (to 0.2 %), every vertex it places
// within max_error of its step from the vessels (measured here on the capsules, not the mesher's
// bins), and TetGen's exact test finds no intersecting faces; a tenth of the triangles or fewer.
TEST(Mesh, DecimationKeepsTopologyVolumeAndSurface) {
  const auto& t = forest().forest.vessels;
  DecimateReport rep;
  DecimateOptions d;
  const auto [fine, m, before, topo] =
      contouredWith([&](SurfaceMesh& s, const std::function<double(std::int32_t, const Vec3&)>& distance) { rep = decimate(s, d, distance); });
  EXPECT_EQ(rep.before, std::int64_t(fine.triangles.size()));
  EXPECT_EQ(rep.after, std::int64_t(m.triangles.size()));
  EXPECT_LT(m.triangles.size() * 10, fine.triangles.size());
  // Collapses keep the volume; flips of nearly flat pairs change it a little (the undecimated
  // volume is within 0.05 % of the union's, WrittenFilesReadBackClosedByVtkWithTheUnionsVolume).
  EXPECT_NEAR(topo.volume_mm3, before.volume_mm3, 2e-3 * before.volume_mm3);
  // Vertices it places stay within max_error steps; the others stay where the volume
  // restoration put them.
  const double worst = largestDistanceOverStep(t, m);
  EXPECT_LE(worst, std::max(largestDistanceOverStep(t, fine), d.max_error) * (1 + 1e-9));
  EXPECT_LE(worst, 0.5);
  const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_decimated_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* f : {"off", "stl"}) {
    std::ofstream out(dir / (std::string("surface.") + f), std::ios::binary);
    meshWriter(f)(out, m);
  }
  const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --self-intersections '" + dir.string() +
                          "' off stl > '" + (dir / "tetgen.json").string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const auto j = nlohmann::json::parse(readText(dir / "tetgen.json"));
  for (const auto& [ext, pairs] : j.items()) EXPECT_EQ(pairs, 0) << ext << ": intersecting face pairs";
  std::cout << fine.triangles.size() << " -> " << m.triangles.size() << " triangles; volume " << before.volume_mm3 << " -> " << topo.volume_mm3
            << " mm^3; largest distance / step " << worst << "; " << j.dump() << "\n";
  std::filesystem::remove_all(dir);
}

// The sliver repair (run on every contour) removes most triangles with an angle under 1° —
// marching tetrahedra leave them where the surface passes by a grid point, and TetGen refines
// around each — and most edges under a fifth of the step; with max_angle 90 (the capped
// default) it removes most triangles with an angle over 100° (TetGen splits the edge an obtuse
// angle faces). It keeps what decimation keeps: topology, closedness, the volume (to 0.05 %),
// vertices within max_error steps of the vessels, and no intersecting faces (TetGen's test).
TEST(Mesh, SliverRepairKeepsTopologyVolumeAndSurface) {
  const auto& t = forest().forest.vessels;
  DecimateReport rep;
  DecimateOptions d;
  d.obtuse_deg = 90;
  const auto [fine, m, before, topo] =
      contouredWith([&](SurfaceMesh& s, const std::function<double(std::int32_t, const Vec3&)>& distance) { rep = repairSlivers(s, d, distance); });
  const auto slivers = [](const SurfaceMesh& s, double degrees) {
    std::int64_t n = 0;
    for (const auto& tri : s.triangles) {
      const Vec3 p[3] = {s.vertices[std::size_t(tri[0])], s.vertices[std::size_t(tri[1])], s.vertices[std::size_t(tri[2])]};
      double smallest = 180;
      for (int i = 0; i < 3; ++i) {
        const Vec3 a = p[(i + 1) % 3] - p[i], b = p[(i + 2) % 3] - p[i];
        smallest = std::min(smallest, std::acos(std::clamp(dot(a, b) / (norm(a) * norm(b)), -1.0, 1.0)) * 180 / std::numbers::pi);
      }
      n += smallest < degrees;
    }
    return n;
  };
  const auto before_1 = slivers(fine, 1), after_1 = slivers(m, 1), before_5 = slivers(fine, 5), after_5 = slivers(m, 5);
  // Triangles with an angle over 100°, and with an edge under a fifth of the smallest step at its ends.
  const auto obtuse = [](const SurfaceMesh& s) {
    std::int64_t n = 0;
    for (const auto& tri : s.triangles) {
      const Vec3 p[3] = {s.vertices[std::size_t(tri[0])], s.vertices[std::size_t(tri[1])], s.vertices[std::size_t(tri[2])]};
      for (int i = 0; i < 3; ++i)
        n += dot(p[(i + 1) % 3] - p[i], p[(i + 2) % 3] - p[i]) <
             std::cos(100 * std::numbers::pi / 180) * norm(p[(i + 1) % 3] - p[i]) * norm(p[(i + 2) % 3] - p[i]);
    }
    return n;
  };
  const auto short_edges = [](const SurfaceMesh& s) {
    std::int64_t n = 0;
    for (const auto& tri : s.triangles)
      for (int i = 0; i < 3; ++i) {
        const auto a = std::size_t(tri[std::size_t(i)]), b = std::size_t(tri[std::size_t((i + 1) % 3)]);
        n += a < b && norm(s.vertices[a] - s.vertices[b]) < 0.2 * std::min(s.vertex_step[a], s.vertex_step[b]);
      }
    return n;
  };
  const auto obtuse_before = obtuse(fine), obtuse_after = obtuse(m), short_before = short_edges(fine), short_after = short_edges(m);
  EXPECT_LT(obtuse_after * 5, obtuse_before);
  EXPECT_LT(short_after * 10, short_before);
  EXPECT_GT(before_1, 100);
  EXPECT_LT(after_1 * 4, before_1);
  EXPECT_LT(after_5 * 2, before_5);
  EXPECT_GT(rep.changes(), before_1);
  EXPECT_EQ(rep.after, std::int64_t(m.triangles.size()));
  EXPECT_NEAR(topo.volume_mm3, before.volume_mm3, 5e-4 * before.volume_mm3);
  EXPECT_LE(largestDistanceOverStep(t, m), std::max(largestDistanceOverStep(t, fine), d.max_error) * (1 + 1e-9));
  const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_slivers_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {
    std::ofstream out(dir / "surface.off", std::ios::binary);
    meshWriter("off")(out, m);
  }
  const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --self-intersections '" + dir.string() +
                          "' off > '" + (dir / "tetgen.json").string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_EQ(nlohmann::json::parse(readText(dir / "tetgen.json"))["off"], 0) << "intersecting face pairs";
  std::cout << "under 1 degree " << before_1 << " -> " << after_1 << ", under 5 degrees " << before_5 << " -> " << after_5 << ", over 100 degrees "
            << obtuse_before << " -> " << obtuse_after << ", edges under 0.2 steps " << short_before << " -> " << short_after << "; " << rep.collapses
            << " collapses, " << rep.flips << " flips, " << rep.moves << " moves; volume " << before.volume_mm3 << " -> " << topo.volume_mm3 << "\n";
  std::filesystem::remove_all(dir);
}

namespace {

// A UV sphere: `rings` bands of `around` quadrilaterals (triangles at the poles), outward.
void addSphere(SurfaceMesh& m, const Vec3& centre, double radius, int rings, int around) {
  const auto first = std::int32_t(m.vertices.size());
  m.vertices.push_back(centre + Vec3(0, 0, radius));
  for (int i = 1; i < rings; ++i)
    for (int j = 0; j < around; ++j) {
      const double th = std::numbers::pi * i / rings, ph = 2 * std::numbers::pi * (j + 0.37 * i) / around;
      m.vertices.push_back(centre + Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)) * radius);
    }
  m.vertices.push_back(centre - Vec3(0, 0, radius));
  const auto at = [&](int i, int j) { return first + 1 + (i - 1) * around + (j % around); };
  const auto south = std::int32_t(m.vertices.size() - 1);
  for (int j = 0; j < around; ++j) {
    m.triangles.push_back({first, at(1, j), at(1, j + 1)});
    for (int i = 1; i + 1 < rings; ++i) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
    m.triangles.push_back({at(rings - 1, j), south, at(rings - 1, j + 1)});
  }
}

// Whether two triangles with no common corner meet: an edge of one through the other (by its
// plane's crossing and barycentric coordinates; the test's own arithmetic).
bool edgesPierce(const std::array<Vec3, 3>& s, const std::array<Vec3, 3>& t) {
  const Vec3 n = cross(t[1] - t[0], t[2] - t[0]);
  for (int i = 0; i < 3; ++i) {
    const Vec3 p = s[std::size_t(i)], q = s[std::size_t((i + 1) % 3)];
    const double dp = dot(n, p - t[0]), dq = dot(n, q - t[0]);
    if (dp * dq > 0 || dp == dq) continue;
    const Vec3 x = p + (q - p) * (dp / (dp - dq));
    const double a = dot(n, cross(t[1] - x, t[2] - x)), b = dot(n, cross(t[2] - x, t[0] - x)), c = dot(n, cross(t[0] - x, t[1] - x));
    if ((a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0)) return true;
  }
  return false;
}

std::vector<std::int32_t> crossingByAllPairs(const SurfaceMesh& m) {
  std::vector<std::int32_t> found;
  const auto corners = [&](std::size_t k) {
    const auto& t = m.triangles[k];
    return std::array<Vec3, 3>{m.vertices[std::size_t(t[0])], m.vertices[std::size_t(t[1])], m.vertices[std::size_t(t[2])]};
  };
  for (std::size_t a = 0; a < m.triangles.size(); ++a)
    for (std::size_t b = a + 1; b < m.triangles.size(); ++b) {
      bool shared = false;
      for (auto u : m.triangles[a])
        for (auto w : m.triangles[b]) shared = shared || u == w;
      if (shared) continue;
      const auto s = corners(a), t = corners(b);
      if (edgesPierce(s, t) || edgesPierce(t, s)) found.push_back(std::int32_t(a)), found.push_back(std::int32_t(b));
    }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

}  // namespace

// The crossing check bins triangles by size and tests each pair in one bin only, and after a
// move only pairs with a triangle that moved or crossed: checked against every pair tested.
TEST(Mesh, CrossingTrianglesAreFoundAcrossSizesAndAgainOnlyWhereVerticesMoved) {
  SurfaceMesh m;
  addSphere(m, Vec3(0, 0, 0), 1.0, 10, 20);         // triangles about 0.3 across
  addSphere(m, Vec3(0.55, 0.1, 0.2), 0.7, 40, 80);  // about 0.05: bins of other levels
  addSphere(m, Vec3(3, 0, 0), 0.5, 12, 24);         // apart from both
  const double cell = 0.02;
  const Vec3 origin(-2.3, -1.1, -1.2);  // below every box, as a lattice's origin is
  const auto expected = crossingByAllPairs(m);
  ASSERT_GT(expected.size(), 300u);
  EXPECT_EQ(crossingTriangles(m, origin, cell), expected);
  const auto first = crossingTriangles(m, origin, cell, true);
  ASSERT_EQ(first.size(), 2u);
  EXPECT_TRUE(std::binary_search(expected.begin(), expected.end(), first[0]) && std::binary_search(expected.begin(), expected.end(), first[1]));

  // The small sphere's cap above z = 0.5 pushed out through the large one, the far sphere moved
  // into its other side (finer triangles, dirty, through coarser ones that are not): crossings go
  // and come.
  const std::size_t small_first = 1 + 9 * 20 + 1, far_first = small_first + 1 + 39 * 80 + 1;
  const auto before = m.vertices;
  for (std::size_t v = small_first; v < far_first; ++v)
    if (m.vertices[v].z > 0.5) m.vertices[v] = m.vertices[v] + Vec3(0.4, 0, 0.3);
  for (std::size_t v = far_first; v < m.vertices.size(); ++v) m.vertices[v] = m.vertices[v] - Vec3(4.1, 0, 0);
  std::vector<char> dirty(m.triangles.size(), 0);
  for (auto k : expected) dirty[std::size_t(k)] = 1;
  std::size_t moved = 0;
  for (std::size_t k = 0; k < m.triangles.size(); ++k)
    for (auto v : m.triangles[k])
      if (m.vertices[std::size_t(v)].x != before[std::size_t(v)].x) dirty[k] = 1, ++moved;
  ASSERT_GT(moved, 0u);
  const auto after = crossingByAllPairs(m);
  ASSERT_NE(after, expected);
  EXPECT_EQ(crossingTriangles(m, origin, cell), after);
  EXPECT_EQ(crossingTriangles(m, origin, cell, false, &dirty), after);
}

// Untangling draws a knot's vertices onto one point: a closed speck of four triangles that no
// crossing check sees (the 100k bench tree's largest part had one, which CGAL found crossing
// itself). It goes; a small sphere a step across stays.
TEST(Mesh, SpecksUntanglingLeavesAreDroppedAndSmallComponentsKept) {
  SurfaceMesh m;
  addSphere(m, Vec3(0, 0, 0), 1.0, 10, 20);
  addSphere(m, Vec3(3, 0, 0), 0.05, 6, 12);
  const auto first = std::int32_t(m.vertices.size());
  const Vec3 p(0.5, 2, 0);
  const double e = 1e-12;
  for (const Vec3& d : {Vec3(0, 0, 0), Vec3(e, 0, 0), Vec3(0, e, 0), Vec3(0, 0, e)}) m.vertices.push_back(p + d);
  for (const auto& t : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}})
    m.triangles.push_back({first + t[0], first + t[1], first + t[2]});
  m.triangle_tree.assign(m.triangles.size(), 0);
  m.vertex_step.assign(m.vertices.size(), 0.1f);
  const auto spheres = m.triangles.size() - 4;
  const auto before = meshTopology(m);
  ASSERT_EQ(before.tree_components[0], 3);
  EXPECT_EQ(removeSpecks(m), 1);
  EXPECT_EQ(m.triangles.size(), spheres);
  EXPECT_EQ(m.vertices.size(), std::size_t(first));
  const auto after = meshTopology(m);
  EXPECT_EQ(after.tree_components[0], 2);
  EXPECT_EQ(after.boundary_edges + after.nonmanifold_edges, 0);
  EXPECT_EQ(removeSpecks(m), 0);
}

// Remeshing (the capped default for contoured parts), on the test forest contoured whole by
// surface nets: what decimation keeps stays (components and Euler characteristic per tree,
// closed, manifold, outward; the volume to 0.1 %; every vertex within max_error steps of the
// vessels; no intersecting faces by TetGen's test), the triangles with an angle of 75° or more
// (the nets' right-angled pairs) fall to under half, and so do those under 15° (TetGen's
// splits, measured on the written surfaces, are CappedAndOpenEndsArePlanarLabelledAndWatertight's).
TEST(Mesh, RemeshingMakesTheNetsTrianglesAcuteAndKeepsTheSurface) {
  const auto& t = forest().forest.vessels;
  SurfaceOptions o;
  o.dual = true;
  SurfaceReport sr;
  const auto nets = vesselSurface(t, o, &sr);
  ASSERT_TRUE(sr.dual) << (sr.dual_refused ? sr.dual_refused : "");
  const auto before = meshTopology(nets);
  DecimateReport rep;
  DecimateOptions d;
  d.sliver_deg = 10, d.obtuse_deg = 90;  // the capped defaults
  o.finish = [&](SurfaceMesh& s, const std::function<double(std::int32_t, const Vec3&)>& distance) {
    rep = remeshIsotropic(s, d, kRemeshTarget, kRemeshRounds, distance);
  };
  const auto m = vesselSurface(t, o, &sr);
  const auto topo = meshTopology(m);
  EXPECT_EQ(topo.boundary_edges, 0);
  EXPECT_EQ(topo.nonmanifold_edges, 0);
  EXPECT_EQ(topo.misoriented_edges, 0);
  EXPECT_EQ(topo.degenerate_triangles, 0);
  EXPECT_EQ(topo.tree_components, before.tree_components);
  EXPECT_EQ(topo.tree_euler, before.tree_euler);
  EXPECT_GT(rep.splits, 0);
  EXPECT_GT(rep.collapses, 0);
  EXPECT_EQ(rep.after, std::int64_t(m.triangles.size()));
  EXPECT_NEAR(topo.volume_mm3, before.volume_mm3, 1e-3 * before.volume_mm3);
  EXPECT_LE(largestDistanceOverStep(t, m), std::max(largestDistanceOverStep(t, nets), d.max_error) * (1 + 1e-9));
  // Triangles by their largest angle: 75° or more; and by their smallest: under 15°.
  const auto count = [](const SurfaceMesh& s, double largest_deg, double smallest_deg) {
    std::int64_t wide = 0, thin = 0;
    for (const auto& tri : s.triangles) {
      const Vec3 p[3] = {s.vertices[std::size_t(tri[0])], s.vertices[std::size_t(tri[1])], s.vertices[std::size_t(tri[2])]};
      double lo = 180, hi = 0;
      for (int i = 0; i < 3; ++i) {
        const Vec3 a = p[(i + 1) % 3] - p[i], b = p[(i + 2) % 3] - p[i];
        const double deg = std::acos(std::clamp(dot(a, b) / (norm(a) * norm(b)), -1.0, 1.0)) * 180 / std::numbers::pi;
        lo = std::min(lo, deg), hi = std::max(hi, deg);
      }
      wide += hi >= largest_deg, thin += lo < smallest_deg;
    }
    return std::pair{wide, thin};
  };
  const auto [wide_before, thin_before] = count(nets, 75, 15);
  const auto [wide_after, thin_after] = count(m, 75, 15);
  EXPECT_GT(wide_before, std::int64_t(nets.triangles.size() / 5));
  EXPECT_LT(wide_after * 2, wide_before);
  EXPECT_LT(thin_after * 2, thin_before);
  const auto dir = std::filesystem::temp_directory_path() / ("angiosynth_mesh_remeshed_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "remeshed");
  {
    std::ofstream out(dir / "remeshed/surface.off", std::ios::binary);
    meshWriter("off")(out, m);
  }
  const std::string cmd = "/usr/bin/python3 '" + (test::sourceDir() / "tests/check_mesh.py").string() + "' --self-intersections '" +
                          (dir / "remeshed").string() + "' off > '" + (dir / "tetgen.json").string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_EQ(nlohmann::json::parse(readText(dir / "tetgen.json"))["off"], 0) << "intersecting face pairs";
  std::cout << nets.triangles.size() << " -> " << m.triangles.size() << " triangles (" << rep.splits << " splits, " << rep.collapses << " collapses, "
            << rep.flips << " flips, " << rep.moves << " moves); largest angle >= 75 deg " << wide_before << " -> " << wide_after
            << ", smallest < 15 deg " << thin_before << " -> " << thin_after << "; volume " << before.volume_mm3 << " -> " << topo.volume_mm3 << "\n";
  std::filesystem::remove_all(dir);
}
