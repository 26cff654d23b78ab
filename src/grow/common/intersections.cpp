#include "grow/common/intersections.hpp"

#include <algorithm>

#include "grow/common/segment_index.hpp"

namespace angiosynth {

bool withinTwoSegments(const VascularTree& t, std::int32_t x, std::int32_t y) {
  // Segments are edges; they are ≤ 2 apart iff some end of y is an end of x or a neighbour of one.
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

std::vector<std::pair<std::int32_t, std::int32_t>> intersectingPairs(const VascularTree& t, const Vec3& lo,
                                                                     const Vec3& hi) {
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  if (t.segmentCount() < 2) return pairs;
  SegmentIndex index(lo, hi);
  index.refresh(t, true);
  double r_max = 0;
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) r_max = std::max(r_max, t.radius[s]);
  // Links are skipped: each lies inside the cap of the vessel ending at its junction.
  for (std::int32_t x = 1; x < t.nodeCount(); ++x) {
    if (t.isRoot(x) || t.isLink(x)) continue;
    const Vec3& a0 = t.position[t.parent[x]];
    const Vec3& a1 = t.position[x];
    const double reach = t.radius[x] + r_max;
    index.forEachNearSegment(a0, a1, reach, [&](std::int32_t y) {
      if (y <= x || t.isLink(y) || withinTwoSegments(t, x, y)) return;
      if (capsulesOverlap(a0, a1, t.radius[x], t.position[t.parent[y]], t.position[y], t.radius[y]))
        pairs.emplace_back(x, y);
    });
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace angiosynth
