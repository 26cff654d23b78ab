#include "grow/common/intersections.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "core/segment_index.hpp"

namespace angiosynth {

bool withinTwoSegments(const VascularTree& t, std::int32_t x, std::int32_t y) {
  // Segments are edges; they are ≤ 2 apart iff some end of y is an end of x or a neighbour of one.
  const auto p = t.parent[x], pp = t.parent[p];
  // Where no node involved is a link (every grown tree), directly: this runs for every pair the
  // collision checks meet.
  const auto plain = [&](std::int32_t v) { return v < 0 || !t.isLink(v); };
  if (plain(x) && plain(p) && plain(pp) && plain(t.sibling(x)) && plain(t.child0[x]) && plain(t.child1[x]) && plain(y) && plain(t.parent[y])) {
    const auto near = [&](std::int32_t v) { return v == p || v == x || v == pp || t.parent[v] == p || t.parent[v] == x; };
    return near(y) || near(t.parent[y]);
  }
  // The nodes of an N-ary junction (joined by links) count as one node.
  thread_local std::vector<std::int32_t> near;
  near.clear();
  for (auto end : {t.parent[x], x}) {
    const auto u = t.junction(end);
    near.push_back(u);
    if (t.parent[u] >= 0) near.push_back(t.junction(t.parent[u]));
    t.junctionChildren(u, near);
  }
  const auto a = t.junction(y), b = t.junction(t.parent[y]);
  return std::find(near.begin(), near.end(), a) != near.end() || std::find(near.begin(), near.end(), b) != near.end();
}

bool joinedAlongVessel(const VascularTree& t, std::int32_t x, std::int32_t y, double reach, double from_prox, double from_dist) {
  const auto continues = [&](std::int32_t v) { return !t.isRoot(v) && t.child0[v] >= 0 && t.child1[v] < 0; };
  int budget = 4096;
  // Down the pieces from c (reached at `at` from the start), while their nodes continue.
  const auto down = [&](std::int32_t c, double at) {
    for (; c >= 0 && at <= reach && budget-- > 0; at += t.length[c], c = continues(c) ? t.child0[c] : -1)
      if (c == y) return true;
    return false;
  };
  const std::int32_t p = t.parent[x];
  if (p >= 0) {
    // Up: the piece ending at x's proximal node, and on while the nodes above continue.
    double at = from_prox;
    for (std::int32_t v = p; !t.isRoot(v) && at <= reach && budget-- > 0; at += t.length[v], v = t.parent[v]) {
      if (v == y) return true;
      if (!continues(t.parent[v])) break;
    }
    // Across: x's siblings at its proximal node, and down their pieces.
    for (std::int32_t c : {t.child0[p], t.child1[p]})
      if (c >= 0 && c != x && down(c, from_prox)) return true;
  }
  // Down: the pieces leaving x's distal node.
  for (std::int32_t c : {t.child0[x], t.child1[x]})
    if (c >= 0 && down(c, from_dist)) return true;
  return false;
}

bool crossInPlane(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const auto side = [](const Vec3& o, const Vec3& u, const Vec3& v) { return (u.x - o.x) * (v.y - o.y) - (u.y - o.y) * (v.x - o.x); };
  const double s1 = side(a, b, c), s2 = side(a, b, d), s3 = side(c, d, a), s4 = side(c, d, b);
  return ((s1 > 0 && s2 < 0) || (s1 < 0 && s2 > 0)) && ((s3 > 0 && s4 < 0) || (s3 < 0 && s4 > 0));
}

bool separatedInPlane(const VascularTree& t, std::int32_t s, const Vec3& p, const std::vector<std::pair<double, std::int32_t>>& near,
                      std::size_t occluders) {
  const Vec3& x0 = t.position[t.parent[s]];
  const Vec3& x1 = t.position[s];
  const std::size_t n = std::min(near.size(), occluders);
  for (std::size_t q = 0; q < n; ++q) {
    const auto y = near[q].second;
    if (y == s) continue;
    const Vec3& y0 = t.position[t.parent[y]];
    const Vec3& y1 = t.position[y];
    if (crossInPlane(p, x0, y0, y1) && crossInPlane(p, x1, y0, y1)) return true;
  }
  return false;
}

std::vector<std::pair<std::int32_t, std::int32_t>> intersectingPairs(const VascularTree& t, const Vec3& lo, const Vec3& hi) {
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  if (t.segmentCount() < 2) return pairs;
  SegmentIndex index(lo, hi);
  index.refresh(t, true);
  // Each pair is sought from its thicker vessel (ties: the smaller id), whose reach 2r covers any
  // thinner one it can touch: the many thin vessels look only close by, not as far as the root's
  // radius. Blocks of segments run in parallel, each with its own list; the lists join in order.
  const auto thinner = [&](std::int32_t y, std::int32_t x) { return t.radius[y] < t.radius[x] || (t.radius[y] == t.radius[x] && y > x); };
  constexpr std::int32_t kBlock = 1024;
  const std::int32_t n = t.nodeCount(), blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<std::pair<std::int32_t, std::int32_t>>> found(static_cast<std::size_t>(blocks));
  tbb::enumerable_thread_specific<SegmentIndex::Marks> marks;
  tbb::parallel_for(std::int32_t(0), blocks, [&](std::int32_t b) {
    auto& m = marks.local();
    for (std::int32_t x = std::max(1, b * kBlock); x < std::min(n, (b + 1) * kBlock); ++x) {
      // Links are skipped: each lies inside the cap of the vessel ending at its junction.
      if (t.isRoot(x) || t.isLink(x)) continue;
      const Vec3& a0 = t.position[t.parent[x]];
      const Vec3& a1 = t.position[x];
      index.forEachNearSegment(a0, a1, 2 * t.radius[x], m, [&](std::int32_t y) {
        if (!thinner(y, x) || t.isLink(y)) return;
        if (overlapsApart(t, x, a0, a1, t.radius[x], y, t.radius[y])) found[std::size_t(b)].emplace_back(std::min(x, y), std::max(x, y));
      });
    }
  });
  for (const auto& f : found) pairs.insert(pairs.end(), f.begin(), f.end());
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace angiosynth
