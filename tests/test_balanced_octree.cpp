// The adaptive grid under the surface mesher (src/mesh/balanced_octree): cells asked for at
// mixed levels give a 2:1-balanced octree whose leaves' tetrahedra form one conforming mesh:
// they fill the covered cells exactly, every inner triangle is shared by exactly two
// tetrahedra (a finer neighbour's vertex never hangs on a coarser face), and only the outer
// boundary of the covered region has unshared triangles.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "mesh/balanced_octree.hpp"

using namespace angiosynth;

namespace {

std::int64_t sixVolume(const std::array<HalfPoint, 4>& t) {  // 6 × signed volume, exact in integers
  std::int64_t d[3][3];
  for (int i = 0; i < 3; ++i)
    for (int a = 0; a < 3; ++a) d[i][a] = t[std::size_t(i + 1)][std::size_t(a)] - t[0][std::size_t(a)];
  return d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
         d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
}

}  // namespace

TEST(BalancedOctree, LeavesSplitIntoAConformingTetrahedralMeshAcrossLevels) {
  const int top = 3;
  std::mt19937_64 rng(7);
  std::vector<std::vector<std::uint64_t>> requests(top + 1);
  // A thin "vessel" of finest cells along a diagonal line, coarse cells scattered around it.
  for (int i = 0; i < 40; ++i) requests[0].push_back(cellCode(80 + i, 80 + i / 2, 90 + i / 3));
  for (int k = 0; k < 30; ++k) {
    const int l = int(rng() % (top + 1));
    const std::int64_t span = 64 >> l;  // the same region at every level
    const std::int64_t off = 64 >> l;
    requests[std::size_t(l)].push_back(
        cellCode(off + std::int64_t(rng() % span), off + std::int64_t(rng() % span), off + std::int64_t(rng() % span)));
  }
  const BalancedOctree octree(top, requests);
  const auto leaves = octree.units(0);  // at level 0 the units are the leaves
  std::map<int, int> per_level;
  for (const auto& l : leaves) ++per_level[l.level];
  ASSERT_GE(per_level.size(), 3u) << "leaves of several levels";

  // Every requested cell is a leaf of its level or refined further.
  std::set<std::tuple<int, std::int64_t, std::int64_t, std::int64_t>> leaf_set;
  for (const auto& l : leaves) leaf_set.insert({l.level, l.cell[0], l.cell[1], l.cell[2]});
  for (int l = 0; l <= top; ++l)
    for (auto code : requests[std::size_t(l)]) {
      const auto c = cellCoords(code);
      EXPECT_TRUE(leaf_set.count({l, c[0], c[1], c[2]}) || octree.refined(l, c[0], c[1], c[2]));
    }

  std::map<std::array<HalfPoint, 3>, int> faces;
  std::int64_t tets = 0;
  std::vector<std::array<HalfPoint, 4>> out;
  LeafSplitter splitter(octree);
  std::vector<OctreeLeaf> unit_leaves;
  std::size_t split = 0;
  for (const auto& unit : octree.units(2)) {
    splitter.leaves(unit, unit_leaves);
    for (const auto& leaf : unit_leaves) {
      ++split;
      out.clear();
      splitter.tetrahedra(leaf, out);
      std::int64_t leaf_volume = 0;
      for (const auto& t : out) {
        const std::int64_t v = std::abs(sixVolume(t));
        ASSERT_GT(v, 0) << "a flat tetrahedron";
        leaf_volume += v;
        ++tets;
        for (int skip = 0; skip < 4; ++skip) {
          std::array<HalfPoint, 3> f;
          int n = 0;
          for (int q = 0; q < 4; ++q)
            if (q != skip) f[std::size_t(n++)] = t[std::size_t(q)];
          std::sort(f.begin(), f.end());
          ++faces[f];
        }
      }
      const std::int64_t edge = std::int64_t(2) << leaf.level;  // half steps
      EXPECT_EQ(leaf_volume, 6 * edge * edge * edge) << "the tetrahedra fill their leaf";
    }
  }
  EXPECT_EQ(split, leaves.size()) << "the units hold every leaf once";
  // Faces used once lie on the boundary of the covered region: a plane of the top cells' lattice
  // beyond which no leaf lies.
  std::int64_t inner = 0, outer = 0;
  const std::int64_t top_edge = std::int64_t(2) << top;
  for (const auto& [f, uses] : faces) {
    ASSERT_LE(uses, 2) << "a triangle in three tetrahedra";
    if (uses == 2) {
      ++inner;
      continue;
    }
    ++outer;
    bool on_top_plane = false;
    for (int a = 0; a < 3; ++a)
      on_top_plane |=
          f[0][std::size_t(a)] == f[1][std::size_t(a)] && f[1][std::size_t(a)] == f[2][std::size_t(a)] && f[0][std::size_t(a)] % top_edge == 0;
    EXPECT_TRUE(on_top_plane) << "an unshared triangle inside the covered region: a crack between levels";
  }
  EXPECT_GT(inner, outer);
  std::cout << leaves.size() << " leaves (" << per_level.size() << " levels), " << tets << " tetrahedra, " << inner << " inner and " << outer
            << " boundary triangles\n";
  // 2:1 balance: a leaf's face neighbour is refined at most once, its children on the face are
  // leaves.
  for (const auto& l : leaves)
    for (int d = -1; d <= 1; d += 2)
      for (int a = 0; a < 3; ++a) {
        auto n = l.cell;
        n[std::size_t(a)] += d;
        if (l.level < 1 || !octree.refined(l.level, n[0], n[1], n[2])) continue;
        for (int k = 0; k < 8; ++k) {
          const std::array<std::int64_t, 3> c{2 * n[0] + (k & 1), 2 * n[1] + ((k >> 1) & 1), 2 * n[2] + ((k >> 2) & 1)};
          if (c[std::size_t(a)] != 2 * n[std::size_t(a)] + (d > 0 ? 0 : 1)) continue;
          EXPECT_FALSE(octree.refined(l.level - 1, c[0], c[1], c[2])) << "levels two apart across a face";
        }
      }
}
