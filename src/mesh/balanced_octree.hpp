#pragma once
// A sparse, 2:1-balanced octree over a lattice (level-0 cells of one grid step; a level-l cell
// spans 2^l steps) and a conforming split of its leaves into tetrahedra, so the surface mesher
// can sample thin vessels finely and thick ones coarsely without cracks between the two.
//
// Cells are asked for by level ("this cell must be a node, refined at least to level l"); the
// octree refines their ancestors, then every neighbour of a refined cell's parent, so leaves
// that touch differ by at most one level. A leaf whose face and edge neighbours are leaves of
// its own level or coarser is split into the six tetrahedra of the Freudenthal (Kuhn) split;
// any other leaf is coned from its centre over its faces, each face square triangulated by a
// rule that depends on the square alone (its diagonal from the lowest to the highest corner if
// no finer vertex lies on its edges, else a fan from its centre), so both cells sharing a face
// triangulate it alike and the tetrahedra of all leaves form one conforming mesh.
#include <array>
#include <cstdint>
#include <vector>

namespace angiosynth {

// Lattice points in half steps (cell and face centres of level-0 cells are odd there).
using HalfPoint = std::array<std::int64_t, 3>;

// Cell coordinates of 21 bits each, packed.
constexpr int kCellBits = 21;
constexpr std::int64_t kCellLimit = std::int64_t(1) << kCellBits;
inline std::uint64_t cellCode(std::int64_t x, std::int64_t y, std::int64_t z) {
  return std::uint64_t(x) | (std::uint64_t(y) << kCellBits) | (std::uint64_t(z) << (2 * kCellBits));
}
inline std::array<std::int64_t, 3> cellCoords(std::uint64_t code) {
  const std::uint64_t m = std::uint64_t(kCellLimit - 1);
  return {std::int64_t(code & m), std::int64_t((code >> kCellBits) & m), std::int64_t(code >> (2 * kCellBits))};
}

// An open-addressing set of 64-bit keys (cell codes); read-only use is thread-safe.
class CodeSet {
 public:
  bool insert(std::uint64_t code);
  bool contains(std::uint64_t code) const;
  std::size_t size() const { return size_; }
  std::vector<std::uint64_t> sorted() const;
  std::size_t bytes() const { return slots_.size() * sizeof(std::uint64_t); }

 private:
  std::size_t slot(std::uint64_t key) const;
  void grow();
  std::vector<std::uint64_t> slots_;  // key + 1; 0 is empty
  std::size_t size_ = 0;
};

struct OctreeLeaf {
  std::int32_t level;
  std::array<std::int64_t, 3> cell;  // at its level
};

class BalancedOctree {
 public:
  // requests[l]: codes of level-l cells that must be nodes of level l (or be refined further).
  // Every requested cell keeps a level-top cell of room to both ends of the coded range: the
  // balance adds neighbours up to the top level.
  BalancedOctree(int top, std::vector<std::vector<std::uint64_t>> requests);

  int top() const { return top_; }
  bool refined(int level, std::int64_t x, std::int64_t y, std::int64_t z) const;
  // Work units that cover the leaves once: the nodes of level `level` (a leaf or a refined cell;
  // the top cells if they are coarser) and the leaves above that level, coarsest first. At level
  // 0 these are all the leaves.
  std::vector<OctreeLeaf> units(int level) const;
  std::size_t bytes() const;

 private:
  int top_;
  std::vector<CodeSet> refined_;  // per level 0 … top + 1
};

// Splits the leaves of one work unit into tetrahedra. The octree's sets are large and every
// query is a cache miss, while a unit's leaves ask about the same few cells around it again and
// again: those answers are kept, for the unit's own level and the two below.
class LeafSplitter {
 public:
  explicit LeafSplitter(const BalancedOctree& octree) : octree_(octree) {}
  // The unit's leaves, depth first, into `out` (cleared).
  void leaves(const OctreeLeaf& unit, std::vector<OctreeLeaf>& out);
  // The leaf's tetrahedra (corners in half steps), appended; the leaf lies in the last unit.
  void tetrahedra(const OctreeLeaf& leaf, std::vector<std::array<HalfPoint, 4>>& out);

 private:
  bool refined(int level, std::int64_t x, std::int64_t y, std::int64_t z);
  void collect(const OctreeLeaf& node, std::vector<OctreeLeaf>& out);
  void square(int level, const HalfPoint& origin, int axis, std::array<std::int64_t, 3> far, const HalfPoint& centre,
              std::vector<std::array<HalfPoint, 4>>& out);
  void edgePoints(int level, const HalfPoint& p, const HalfPoint& q, std::vector<HalfPoint>& out);

  const BalancedOctree& octree_;
  struct Window {
    std::array<std::int64_t, 3> lo{};  // first cell (the unit's first, less one)
    std::int64_t n = 0;                // cells along each axis
    std::vector<std::int8_t> known;    // −1 unknown, 0, 1
  };
  int unit_level_ = -1;
  std::array<Window, 3> windows_;  // unit level, one below, two below
  std::vector<HalfPoint> ring_;    // a face's corners and edge points, reused: faces are many and small
};

}  // namespace angiosynth
