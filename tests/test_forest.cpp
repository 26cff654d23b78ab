// Forests: several trees in one VascularTree (one root each), and everything downstream that
// must know which tree and which kind a vessel belongs to: graph files and the classes volume.
// The forest here is a real CCO tree (artery) and a copy of it moved beside it (vein).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "cli_run.hpp"
#include "core/forest.hpp"
#include "core/units.hpp"
#include "domain/growth_domain.hpp"
#include "grow/cco/grower.hpp"
#include "grow/common/intersections.hpp"
#include "io/graph_writers.hpp"
#include "io/volume_writers.hpp"
#include "raster/ground_truth.hpp"

namespace angiosynth {
namespace {

namespace fs = std::filesystem;

// A CCO tree in a sphere of radius 10 mm and the same tree 24 mm further along x, as artery and vein.
Forest twoTreeForest() {
  static const Forest forest = [] {
    const auto d = GrowthDomain::analytic(DomainShape::Sphere, 10, 0.5);
    CcoOptions o;
    o.terminals = 300;
    o.root_mm = d.defaultRoot();
    o.physics.perfusion_flow = 100;
    o.physics.total_terminals = 300;
    GrowthReport rep;
    const VascularTree a = growCco(d, o, rep);
    VascularTree b = a;
    for (auto& p : b.position) p.x += 24;
    Forest f;
    f.vessels.appendTree(a, 0);
    f.vessels.appendTree(b, 1);
    f.trees = {{"artery", "artery", 0}, {"vein", "vein", 0}};
    assignClassLabels(f.trees);
    return f;
  }();
  return forest;
}

TEST(Forest, TreesKeepTheirRootsTopologyAndNoVesselOfOneTouchesAnother) {
  const Forest f = twoTreeForest();
  const VascularTree& t = f.vessels;
  const auto roots = t.roots();
  ASSERT_EQ(roots.size(), 2u);
  EXPECT_EQ(roots[0], 0);
  EXPECT_EQ(roots[1], t.nodeCount() / 2);
  EXPECT_EQ(t.totalTerminals(), 600);
  EXPECT_EQ(f.trees[0].class_label, 1);
  EXPECT_EQ(f.trees[1].class_label, 2);
  // Top-down order visits every node once, each after its parent, tree after tree.
  const auto order = t.topDownOrder();
  ASSERT_EQ(order.size(), std::size_t(t.nodeCount()));
  std::vector<int> seen(t.nodeCount(), 0);
  for (auto i : order) {
    if (!t.isRoot(i)) { EXPECT_TRUE(seen[t.parent[i]]) << i; }
    EXPECT_EQ(t.tree[i], i < roots[1] ? 0 : 1);
    seen[i] = 1;
  }
  // Brute force over all pairs across the trees, and the forest-wide check within them.
  std::int64_t across = 0;
  for (std::int32_t x = 1; x < t.nodeCount(); ++x)
    for (std::int32_t y = x + 1; y < t.nodeCount(); ++y)
      if (!t.isRoot(x) && !t.isRoot(y) && t.tree[x] != t.tree[y])
        across += capsulesOverlap(t.position[t.parent[x]], t.position[x], t.radius[x], t.position[t.parent[y]], t.position[y], t.radius[y]);
  EXPECT_EQ(across, 0);
  EXPECT_TRUE(intersectingPairs(t, Vec3(-1, -1, -1), Vec3(50, 30, 30)).empty());
  // Removing a subtree keeps both roots and their trees.
  VascularTree pruned = t;
  pruned.removeSubtrees({t.child0[t.child0[roots[1]]]});
  EXPECT_EQ(pruned.roots().size(), 2u);
  EXPECT_LT(pruned.totalTerminals(), 600);
  EXPECT_EQ(pruned.tree.back(), 1);
}

TEST(Forest, GraphFilesNameTreeAndKindAndLoadAsOneTreePerInlet) {
  const Forest f = twoTreeForest();
  const fs::path dir = freshTestDir("angiosynth_forest_graph_");
  const auto write = [&](const char* name, auto&& w) {
    std::ofstream o(dir / name);
    w(o);
  };
  write("tree.graphml", [&](std::ostream& o) { writeGraphml(o, f.vessels, f.trees); });
  write("tree.swc", [&](std::ostream& o) { writeSwc(o, f.vessels, f.trees); });
  write("edges.csv", [&](std::ostream& o) { writeEdgesCsv(o, f.vessels, f.trees); });
  write("tree.gxl", [&](std::ostream& o) { writeGxl(o, f.vessels, f.trees, GraphFrame{}, "forest"); });
  const std::string out = debianPython(R"(
import networkx as nx, csv, collections
g = nx.read_graphml('tree.graphml')
comps = list(nx.weakly_connected_components(g))
print('components', len(comps), all(nx.is_tree(g.subgraph(c).to_undirected()) for c in comps))
kinds = sorted({tuple(sorted({g.nodes[n]['kind'] for n in c})) for c in comps})
print('kinds', kinds)
print('edge kinds agree', all(g.edges[e]['kind'] == g.nodes[e[1]]['kind'] for e in g.edges))
rows = [l.split() for l in open('tree.swc') if not l.startswith('#')]
print('swc roots', sum(r[6] == '-1' for r in rows), 'types', sorted({r[1] for r in rows}))
c = collections.Counter(r['kind'] for r in csv.DictReader(open('edges.csv')))
print('csv', c['artery'], c['vein'])
)",
                                       dir);
  const auto segments = f.vessels.nodeCount() / 2 - 1;
  EXPECT_NE(out.find("components 2 True"), std::string::npos) << out;
  EXPECT_NE(out.find("kinds [('artery',), ('vein',)]"), std::string::npos) << out;
  EXPECT_NE(out.find("edge kinds agree True"), std::string::npos) << out;
  EXPECT_NE(out.find("swc roots 2 types ['1', '2', '3']"), std::string::npos) << out;
  EXPECT_NE(out.find("csv " + std::to_string(segments) + " " + std::to_string(segments)), std::string::npos) << out;
  const std::string gxl = slurp(dir / "tree.gxl");
  EXPECT_NE(gxl.find("<attr name=\"kind\"><string>vein</string></attr>"), std::string::npos);
  fs::remove_all(dir);
}

// An artery and a vein grown together in one sphere at the density and voxel size of
// examples/cco_artery_vein_3d.toml (40 terminals per cm^3 of each kind, 0.3 mm voxels), where
// thin vessels of the two kinds pass within a voxel of each other.
Forest interleavedForest(VolumeGrid& g) {
  const auto d = GrowthDomain::analytic(DomainShape::Sphere, 19, 0.3);
  CcoOptions o;
  o.terminals = 1200;
  o.physics.perfusion_flow = 500 * 1e3 / 60;
  o.physics.total_terminals = 1200;
  o.seed = 3;
  const Vec3 c = d.center();
  const double s = std::sqrt(19.0 * 19.0 - 4.0);
  std::vector<CcoInlet> in(2);
  in[0] = {c + Vec3(-2, s, 0), 0, 0, 100 * kPaPerMmHg, 60 * kPaPerMmHg};
  in[1] = {c + Vec3(2, s, 0), 1, 0, 5 * kPaPerMmHg, 20 * kPaPerMmHg};
  GrowthReport rep;
  const auto trees = growCcoForest(d, o, in, rep);
  Forest f;
  for (int k = 0; k < 2; ++k) f.vessels.appendTree(trees[k], k);
  f.trees = {{"artery", "artery", 0}, {"vein", "vein", 0}};
  assignClassLabels(f.trees);
  g.spacing_mm = Vec3(0.3, 0.3, 0.3);
  g.origin_mm = Vec3(0.15, 0.15, 0.15);  // the centre of voxel (0, 0, 0); the domain starts at 0
  g.dims = GrowthDomain::analyticDims(DomainShape::Sphere, 19, 0.3);
  return f;
}

// The classes volume, read back with nibabel: every mask voxel carries exactly one kind, and at
// least 99.9 % of each tree's centreline samples lie in voxels of its kind (the partial-volume
// rule alone leaves the vein, the wider tree, near 99.86 % in the example).
TEST(Forest, ClassesVolumeGivesEveryMaskVoxelOneKindAndEachCentrelineItsOwn) {
  VolumeGrid g;
  const Forest f = interleavedForest(g);
  const VascularTree& t = f.vessels;
  GroundTruthVolumes gt = rasterizeGroundTruth(t, g, RasterOptions{2});
  fillClasses(gt, t, segmentClasses(t, f.trees));
  const fs::path dir = freshTestDir("angiosynth_forest_classes_");
  writeNifti(dir / "classes.nii.gz", viewOf(gt.classes, true, "classes"));
  writeNifti(dir / "mask.nii.gz", viewOf(gt.mask, true, "mask"));
  // Centreline samples every quarter voxel, each with its tree's class, as text for Python.
  {
    std::ofstream s(dir / "samples.txt");
    for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
      if (t.isRoot(i)) continue;
      const Vec3 a = t.position[t.parent[i]], b = t.position[i];
      const int n = std::max(1, int(std::ceil(t.length[i] / (g.spacing_mm.x / 4))));
      for (int k = 0; k <= n; ++k) {
        const Vec3 v = g.index(a + (b - a) * (double(k) / n));
        // Voxel i covers [i - 1/2, i + 1/2).
        s << std::floor(v.x + 0.5) << ' ' << std::floor(v.y + 0.5) << ' ' << std::floor(v.z + 0.5) << ' ' << f.trees[t.tree[i]].class_label << '\n';
      }
    }
  }
  const std::string out = debianPython(R"(
import nibabel as nib, numpy as np
c = np.asarray(nib.load('classes.nii.gz').dataobj); m = np.asarray(nib.load('mask.nii.gz').dataobj)
print('mask', int(m.sum()), 'unlabelled', int(((m > 0) & (c == 0)).sum()), 'outside', int(((m == 0) & (c > 0)).sum()),
      'kinds', sorted(int(x) for x in np.unique(c)))
s = np.loadtxt('samples.txt', dtype=int)
for k in (1, 2):
    q = s[s[:, 3] == k]
    print('class', k, 'share %.5f' % np.mean(c[q[:, 0], q[:, 1], q[:, 2]] == k), 'of', len(q))
)",
                                       dir);
  std::cout << out;
  EXPECT_NE(out.find("unlabelled 0 outside 0 kinds [0, 1, 2]"), std::string::npos) << out;
  for (int k : {1, 2}) {
    const auto at = out.find("class " + std::to_string(k) + " share ");
    ASSERT_NE(at, std::string::npos) << out;
    EXPECT_GE(std::stod(out.substr(at + 14)), 0.999) << out;
  }
  fs::remove_all(dir);
}

// The rule for voxels two kinds share, on segments placed by hand (1 mm voxels): a thin vein
// whose centreline runs through the artery's partial volume keeps every voxel its centreline
// crosses; where a thin artery and a thin vein cross one voxel, the one with the shorter course
// keeps it, so the loss falls on the kind for which the voxel is the smaller share.
TEST(Forest, AVoxelTwoKindsShareGoesToTheThinVesselThatCrossesItThenToTheShorterCourse) {
  const auto segment = [](const Vec3& a, const Vec3& b, double r) {
    VascularTree t;
    t.addNode(a, -1);
    t.addNode(b, 0);
    t.radius[1] = r;
    return t;
  };
  Forest f;
  // A thick artery, and 0.01 mm from its surface a thin vein whose voxels (centres 2.6 mm from
  // the artery's axis) lie mostly inside the artery.
  f.vessels.appendTree(segment(Vec3(2, 10.9, 10.5), Vec3(30, 10.9, 10.5), 3.0), 0);
  f.vessels.appendTree(segment(Vec3(2, 13.95, 10.5), Vec3(30, 13.95, 10.5), 0.04), 1);
  f.vessels.appendTree(segment(Vec3(10.5, 2, 25.5), Vec3(10.5, 30, 25.5), 0.05), 0);  // long thin artery
  f.vessels.appendTree(segment(Vec3(6, 2.2, 25.7), Vec3(15, 2.2, 25.7), 0.1), 1);     // short thin vein crossing its first voxel
  f.trees = {{"artery", "artery", 0}, {"vein", "vein", 0}};
  assignClassLabels(f.trees);
  VolumeGrid g;
  g.dims = {33, 33, 33};
  g.spacing_mm = Vec3(1, 1, 1);
  g.origin_mm = Vec3(0.5, 0.5, 0.5);
  GroundTruthVolumes gt = rasterizeGroundTruth(f.vessels, g, RasterOptions{4});
  const auto classes = segmentClasses(f.vessels, f.trees);
  fillClasses(gt, f.vessels, classes);
  const VascularTree& t = f.vessels;
  int vein_in_artery_pv = 0;
  for (std::int32_t s : {3, 7}) {  // the veins' segments
    forEachCrossedVoxel(g, t.position[t.parent[s]], t.position[s], [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      EXPECT_EQ(gt.classes.at(i, j, k), 2) << i << ' ' << j << ' ' << k;
      vein_in_artery_pv += classes[gt.instances.at(i, j, k)] == 1;
    });
  }
  EXPECT_GT(vein_in_artery_pv, 10);  // the partial-volume rule alone gives these voxels to the artery
  // The long artery loses only the voxel it shares with the short vein, and keeps its others.
  int artery_kept = 0, artery_voxels = 0;
  forEachCrossedVoxel(g, t.position[4], t.position[5], [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    ++artery_voxels;
    artery_kept += gt.classes.at(i, j, k) == 1;
  });
  EXPECT_EQ(artery_kept, artery_voxels - 1);
  for (std::size_t v = 0; v < gt.mask.data.size(); ++v) EXPECT_EQ(gt.mask.data[v] != 0, gt.classes.data[v] != 0) << v;
}

}  // namespace
}  // namespace angiosynth
