#pragma once
// Geometry invariants of grown trees, checked independently of the grower's own index: brute
// force over all pairs, and the domain's depth sampled along every centreline.
#include <gtest/gtest.h>

#include <algorithm>

#include "domain/growth_domain.hpp"
#include "grow/common/intersections.hpp"

namespace angiosynth::test {

// Every pair of segments more than one segment apart (within and across the trees of a forest)
// whose capsules overlap, by brute force (independent of the grid the grower and its final check
// use), as (smaller id, larger id) in order.
inline std::vector<std::pair<std::int32_t, std::int32_t>> bruteForcePairs(const VascularTree& t) {
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  for (std::int32_t x = 1; x < t.nodeCount(); ++x)
    for (std::int32_t y = x + 1; y < t.nodeCount(); ++y) {
      if (t.isRoot(x) || t.isRoot(y)) continue;  // a forest: the roots of later trees
      const Vec3 &a0 = t.position[t.parent[x]], &a1 = t.position[x], &b0 = t.position[t.parent[y]], &b1 = t.position[y];
      // Bounding boxes first.
      bool apart = false;
      for (int ax = 0; ax < 3 && !apart; ++ax)
        apart = std::min(a0[ax], a1[ax]) - t.radius[x] > std::max(b0[ax], b1[ax]) + t.radius[y] ||
                std::min(b0[ax], b1[ax]) - t.radius[y] > std::max(a0[ax], a1[ax]) + t.radius[x];
      if (apart) continue;
      if (withinTwoSegments(t, x, y)) continue;
      if (segmentSegmentDistance(a0, a1, b0, b1) < t.radius[x] + t.radius[y]) pairs.emplace_back(x, y);
    }
  return pairs;
}
inline std::int64_t bruteForceIntersections(const VascularTree& t) { return std::int64_t(bruteForcePairs(t).size()); }

// Geometry invariants of a final tree: length > 2r, inside the domain (checked by sampling the
// capsule's centreline against the domain's depth), no intersecting pair.
inline void expectGeometry(const VascularTree& t, const GrowthDomain& d) {
  std::int64_t short_segments = 0, outside = 0;
  for (std::int32_t s = 1; s < t.nodeCount(); ++s) {
    if (!(t.length[s] > 2 * t.radius[s])) ++short_segments;
    const Vec3 a = t.position[t.parent[s]], b = t.position[s];
    for (int k = 0; k <= 64; ++k) {
      const Vec3 p = a + (b - a) * (k / 64.0);
      const double from_root = distance(p, t.position[0]);
      const double need = t.parent[s] == 0 ? std::min(t.radius[s], from_root - t.radius[s]) : t.radius[s];
      if (d.depth(p) < need - 1e-9) {
        ++outside;
        break;
      }
    }
  }
  EXPECT_EQ(short_segments, 0);
  EXPECT_EQ(outside, 0);
  EXPECT_EQ(bruteForceIntersections(t), 0);
}

}  // namespace angiosynth::test
