#include "mesh/balanced_octree.hpp"

#include <algorithm>

namespace angiosynth {
namespace {

std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

std::uint64_t parentCode(std::uint64_t code) {
  const auto c = cellCoords(code);
  return cellCode(c[0] >> 1, c[1] >> 1, c[2] >> 1);
}

}  // namespace

std::size_t CodeSet::slot(std::uint64_t key) const {
  const std::size_t mask = slots_.size() - 1;
  std::size_t i = mix(key) & mask;
  while (slots_[i] != 0 && slots_[i] != key + 1) i = (i + 1) & mask;
  return i;
}

void CodeSet::grow() {
  std::vector<std::uint64_t> old = std::move(slots_);
  slots_.assign(std::max<std::size_t>(64, old.size() * 2), 0);
  for (auto k : old)
    if (k != 0) slots_[slot(k - 1)] = k;
}

bool CodeSet::insert(std::uint64_t code) {
  if (2 * (size_ + 1) > slots_.size()) grow();
  const auto i = slot(code);
  if (slots_[i] != 0) return false;
  slots_[i] = code + 1;
  ++size_;
  return true;
}

bool CodeSet::contains(std::uint64_t code) const { return !slots_.empty() && slots_[slot(code)] != 0; }

std::vector<std::uint64_t> CodeSet::sorted() const {
  std::vector<std::uint64_t> out;
  out.reserve(size_);
  for (auto k : slots_)
    if (k != 0) out.push_back(k - 1);
  std::sort(out.begin(), out.end());
  return out;
}

BalancedOctree::BalancedOctree(int top, std::vector<std::vector<std::uint64_t>> requests) : top_(top), refined_(std::size_t(top + 2)) {
  requests.resize(std::size_t(top + 1));
  for (int l = 0; l <= top; ++l)
    for (auto code : requests[std::size_t(l)]) refined_[std::size_t(l + 1)].insert(parentCode(code));
  // Fine to coarse: a refined cell needs its parent refined and, for the balance, each of its 26
  // neighbours to be a node (their parents refined). Insertions go one level up only, so one
  // pass suffices.
  for (int l = 1; l <= top; ++l)
    for (auto code : refined_[std::size_t(l)].sorted()) {
      // The 27 cells around it have at most two parents along each axis.
      const auto c = cellCoords(code);
      std::int64_t lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::max<std::int64_t>(0, c[std::size_t(a)] - 1) >> 1;
        hi[a] = std::min<std::int64_t>(kCellLimit - 1, c[std::size_t(a)] + 1) >> 1;
      }
      for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
        for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
          for (std::int64_t x = lo[0]; x <= hi[0]; ++x) refined_[std::size_t(l + 1)].insert(cellCode(x, y, z));
    }
}

bool BalancedOctree::refined(int level, std::int64_t x, std::int64_t y, std::int64_t z) const {
  if (level <= 0 || level > top_ + 1 || x < 0 || y < 0 || z < 0 || x >= kCellLimit || y >= kCellLimit || z >= kCellLimit) return false;
  return refined_[std::size_t(level)].contains(cellCode(x, y, z));
}

std::vector<OctreeLeaf> BalancedOctree::units(int level) const {
  std::vector<OctreeLeaf> out;
  if (level > top_) {
    for (auto code : refined_[std::size_t(top_ + 1)].sorted()) out.push_back({top_ + 1, cellCoords(code)});
    return out;
  }
  for (int l = top_; l >= level; --l)
    for (auto code : refined_[std::size_t(l + 1)].sorted()) {
      const auto p = cellCoords(code);
      for (int c = 0; c < 8; ++c) {
        const std::array<std::int64_t, 3> cell{2 * p[0] + (c & 1), 2 * p[1] + ((c >> 1) & 1), 2 * p[2] + ((c >> 2) & 1)};
        if (l == level || !refined(l, cell[0], cell[1], cell[2])) out.push_back({l, cell});
      }
    }
  return out;
}

std::size_t BalancedOctree::bytes() const {
  std::size_t b = 0;
  for (const auto& s : refined_) b += s.bytes();
  return b;
}

void LeafSplitter::leaves(const OctreeLeaf& unit, std::vector<OctreeLeaf>& out) {
  unit_level_ = unit.level;
  for (int k = 0; k < 3; ++k) {
    auto& w = windows_[std::size_t(k)];
    const int l = unit.level - k;
    if (l < 1) {
      w.n = 0;
      continue;
    }
    for (int a = 0; a < 3; ++a) w.lo[std::size_t(a)] = (unit.cell[std::size_t(a)] << k) - 1;
    w.n = (std::int64_t(1) << k) + 2;
    w.known.assign(std::size_t(w.n * w.n * w.n), -1);
  }
  out.clear();
  collect(unit, out);
}

bool LeafSplitter::refined(int level, std::int64_t x, std::int64_t y, std::int64_t z) {
  const int k = unit_level_ - level;
  if (k >= 0 && k < 3 && windows_[std::size_t(k)].n > 0) {
    auto& w = windows_[std::size_t(k)];
    const std::int64_t i = x - w.lo[0], j = y - w.lo[1], m = z - w.lo[2];
    if (i >= 0 && j >= 0 && m >= 0 && i < w.n && j < w.n && m < w.n) {
      auto& v = w.known[std::size_t(i + w.n * (j + w.n * m))];
      if (v < 0) v = octree_.refined(level, x, y, z) ? 1 : 0;
      return v == 1;
    }
  }
  return octree_.refined(level, x, y, z);
}

void LeafSplitter::collect(const OctreeLeaf& node, std::vector<OctreeLeaf>& out) {
  if (!refined(node.level, node.cell[0], node.cell[1], node.cell[2])) {
    out.push_back(node);
    return;
  }
  for (int c = 0; c < 8; ++c)
    collect({node.level - 1, {2 * node.cell[0] + (c & 1), 2 * node.cell[1] + ((c >> 1) & 1), 2 * node.cell[2] + ((c >> 2) & 1)}}, out);
}

void LeafSplitter::edgePoints(int level, const HalfPoint& p, const HalfPoint& q, std::vector<HalfPoint>& out) {
  if (level == 0) return;
  int along = 0;
  while (p[std::size_t(along)] == q[std::size_t(along)]) ++along;
  // The four level-`level` cells around the edge: the edge's own span along it, and the cells on
  // both sides of its lines in the two other axes.
  const int shift = level + 1;
  std::array<std::int64_t, 3> lo;
  for (int a = 0; a < 3; ++a) lo[std::size_t(a)] = std::min(p[std::size_t(a)], q[std::size_t(a)]) >> shift;
  const int u = (along + 1) % 3, v = (along + 2) % 3;
  bool split = false;
  for (int du = -1; du <= 0 && !split; ++du)
    for (int dv = -1; dv <= 0 && !split; ++dv) {
      auto c = lo;
      c[std::size_t(u)] += du;
      c[std::size_t(v)] += dv;
      split = refined(level, c[0], c[1], c[2]);
    }
  if (!split) return;
  HalfPoint mid;
  for (int a = 0; a < 3; ++a) mid[std::size_t(a)] = (p[std::size_t(a)] + q[std::size_t(a)]) / 2;
  edgePoints(level - 1, p, mid, out);
  out.push_back(mid);
  edgePoints(level - 1, mid, q, out);
}

void LeafSplitter::square(int level, const HalfPoint& origin, int axis, std::array<std::int64_t, 3> far, const HalfPoint& centre,
                          std::vector<std::array<HalfPoint, 4>>& out) {
  const std::int64_t size = std::int64_t(2) << level;  // in half steps
  const int b = (axis + 1) % 3, c = (axis + 2) % 3;
  if (refined(level, far[0], far[1], far[2])) {
    // The far cell's children on this face meet it in four squares of the level below.
    const std::int64_t near_child = far[std::size_t(axis)] * size == origin[std::size_t(axis)] ? 0 : 1;
    for (int k = 0; k < 4; ++k) {
      HalfPoint o = origin;
      o[std::size_t(b)] += (k & 1) * size / 2;
      o[std::size_t(c)] += (k >> 1) * size / 2;
      std::array<std::int64_t, 3> child{2 * far[0], 2 * far[1], 2 * far[2]};
      child[std::size_t(axis)] += near_child;
      child[std::size_t(b)] += k & 1;
      child[std::size_t(c)] += k >> 1;
      square(level - 1, o, axis, child, centre, out);
    }
    return;
  }
  HalfPoint corner[4] = {origin, origin, origin, origin};
  corner[1][std::size_t(b)] += size;
  corner[2][std::size_t(b)] += size;
  corner[2][std::size_t(c)] += size;
  corner[3][std::size_t(c)] += size;
  auto& ring = ring_;
  ring.clear();
  for (int k = 0; k < 4; ++k) {
    ring.push_back(corner[k]);
    edgePoints(level, corner[k], corner[(k + 1) % 4], ring);
  }
  if (ring.size() == 4) {  // the diagonal from the lowest corner to the highest, as Freudenthal's
    out.push_back({centre, corner[0], corner[1], corner[2]});
    out.push_back({centre, corner[0], corner[3], corner[2]});
    return;
  }
  HalfPoint mid = origin;
  mid[std::size_t(b)] += size / 2;
  mid[std::size_t(c)] += size / 2;
  for (std::size_t k = 0; k < ring.size(); ++k) out.push_back({centre, mid, ring[k], ring[(k + 1) % ring.size()]});
}

void LeafSplitter::tetrahedra(const OctreeLeaf& leaf, std::vector<std::array<HalfPoint, 4>>& out) {
  const int l = leaf.level;
  const std::int64_t size = std::int64_t(2) << l;
  const HalfPoint o{leaf.cell[0] * size, leaf.cell[1] * size, leaf.cell[2] * size};
  // Plain: no finer leaf touches a face or an edge (corner neighbours add no vertex).
  bool plain = true;
  for (int dz = -1; dz <= 1 && plain; ++dz)
    for (int dy = -1; dy <= 1 && plain; ++dy)
      for (int dx = -1; dx <= 1 && plain; ++dx) {
        const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
        if (nonzero == 1 || nonzero == 2) plain = !refined(l, leaf.cell[0] + dx, leaf.cell[1] + dy, leaf.cell[2] + dz);
      }
  if (plain) {
    static constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    for (const auto& t : kTets) {
      std::array<HalfPoint, 4> tet;
      for (int q = 0; q < 4; ++q) tet[std::size_t(q)] = {o[0] + size * (t[q] & 1), o[1] + size * ((t[q] >> 1) & 1), o[2] + size * ((t[q] >> 2) & 1)};
      out.push_back(tet);
    }
    return;
  }
  const HalfPoint centre{o[0] + size / 2, o[1] + size / 2, o[2] + size / 2};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      HalfPoint face = o;
      face[std::size_t(axis)] += side * size;
      auto far = leaf.cell;
      far[std::size_t(axis)] += side ? 1 : -1;
      square(l, face, axis, far, centre, out);
    }
}

}  // namespace angiosynth
