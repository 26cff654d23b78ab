#include "grow/common/intersections.hpp"

#include <algorithm>

#include "grow/common/segment_index.hpp"

namespace angiosynth {

bool withinTwoSegments(const VascularTree& t, std::int32_t x, std::int32_t y) {
  // Segments are edges; they are ≤ 2 apart iff some end of y is an end of x or a neighbour of one.
  std::int32_t near[8];
  int n = 0;
  for (auto u : {t.parent[x], x}) {
    near[n++] = u;
    if (t.parent[u] >= 0) near[n++] = t.parent[u];
    if (t.child0[u] >= 0) near[n++] = t.child0[u];
    if (t.child1[u] >= 0) near[n++] = t.child1[u];
  }
  for (int i = 0; i < n; ++i)
    if (near[i] == y || near[i] == t.parent[y]) return true;
  return false;
}

std::vector<std::pair<std::int32_t, std::int32_t>> intersectingPairs(const VascularTree& t, const Vec3& lo,
                                                                     const Vec3& hi) {
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  if (t.segmentCount() < 2) return pairs;
  SegmentIndex index(lo, hi);
  index.refresh(t, true);
  double r_max = 0;
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) r_max = std::max(r_max, t.radius[s]);
  for (std::int32_t x = 1; x < t.nodeCount(); ++x) {
    if (t.isRoot(x)) continue;
    const Vec3& a0 = t.position[t.parent[x]];
    const Vec3& a1 = t.position[x];
    const double reach = t.radius[x] + r_max;
    index.forEachNearSegment(a0, a1, reach, [&](std::int32_t y) {
      if (y <= x || withinTwoSegments(t, x, y)) return;
      if (capsulesOverlap(a0, a1, t.radius[x], t.position[t.parent[y]], t.position[y], t.radius[y]))
        pairs.emplace_back(x, y);
    });
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace angiosynth
