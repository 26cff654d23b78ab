#pragma once
// Vessels are capsules (cylinders with spherical caps). Two segments "intersect" when their
// capsules overlap and they are more than two segments apart: pairs that share a node, or that
// have one segment between them, necessarily touch at a joint and are exempt.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/vascular_tree.hpp"

namespace angiosynth {

// True if segments x and y share a node or one segment lies between them.
bool withinTwoSegments(const VascularTree& tree, std::int32_t x, std::int32_t y);

// True if y is a piece of the vessel x lies on (or branches from) within `reach` mm: reached from
// x's ends along the tree through nodes of one child only (a vessel given as a polyline, whose
// pieces overlap at every bend once they are shorter than their radius). The nodes at x's own
// ends may be junctions. `from_prox` and `from_dist`: how far the point the walk starts from lies
// from x's proximal and distal node (x's ends: 0, 0). At most 4096 pieces are walked.
bool joinedAlongVessel(const VascularTree& tree, std::int32_t x, std::int32_t y, double reach, double from_prox = 0, double from_dist = 0);

inline bool capsulesOverlap(const Vec3& a0, const Vec3& a1, double ra, const Vec3& b0, const Vec3& b1, double rb) {
  // Most pairs a query meets have boxes apart by more than the radii along some axis; they are
  // told apart without the distance. The margin is far above the distance's rounding, so the
  // answer is the distance's.
  const double reach = (ra + rb) * (1 + 1e-9);
  const auto apart = [reach](double p, double q, double u, double v) {
    return std::min(u, v) - std::max(p, q) > reach || std::min(p, q) - std::max(u, v) > reach;
  };
  if (apart(a0.x, a1.x, b0.x, b1.x) || apart(a0.y, a1.y, b0.y, b1.y) || apart(a0.z, a1.z, b0.z, b1.z)) return false;
  return segmentSegmentDistance(a0, a1, b0, b1) < ra + rb;
}

// True if segment y, of radius ry, overlaps the capsule a–e of radius r that segment x occupies
// (or is about to) and lies more than two segments from x. The distance first: most candidates a
// query meets are apart, and the test of the tree's neighbourhood reads up to eight scattered
// nodes where the distance reads two.
inline bool overlapsApart(const VascularTree& t, std::int32_t x, const Vec3& a, const Vec3& e, double r, std::int32_t y, double ry) {
  return capsulesOverlap(a, e, r, t.position[t.parent[y]], t.position[y], ry) && !withinTwoSegments(t, x, y);
}

// True if the capsule a–e of radius r, which segment x occupies (or is about to), overlaps a
// vessel more than two segments from x. `for_each_candidate(f)` calls f(y) for the segments to
// consider (e.g. SegmentIndex::forEachNearSegment); `radius_of(y)` gives y's radius.
template <class Candidates, class Radius>
bool overlapsOtherVessel(const VascularTree& t, std::int32_t x, const Vec3& a, const Vec3& e, double r, Candidates&& for_each_candidate,
                         Radius&& radius_of) {
  bool hit = false;
  for_each_candidate([&](std::int32_t y) {
    if (hit || y == x || y >= t.nodeCount()) return;
    hit = overlapsApart(t, x, a, e, r, y, radius_of(y));
  });
  return hit;
}

// True if segments a–b and c–d cross at a point inside both, in the plane z = const.
bool crossInPlane(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// True if, in the plane, one of the first `occluders` segments of `near` cuts both sides p–x0
// and p–x1 of the triangle of point p and segment s = x0–x1. That vessel then separates p from
// s inside the triangle, and a bifurcation b there joins them only across it (x0–b and b–x1
// cross it if b is on p's side, b–p otherwise), which a collision check refuses whatever the
// radii: the vessel shares no end with x0 or x1, so it is more than two segments from the one
// that crosses it. CCO tries bifurcations in the triangle only: Kamiya's point is a weighted
// mean of the three ends, and the tree's volume grows with each of the three lengths, so its
// minimum lies there too (projecting b onto the triangle shortens all three).
bool separatedInPlane(const VascularTree& t, std::int32_t s, const Vec3& p, const std::vector<std::pair<double, std::int32_t>>& near,
                      std::size_t occluders);

// Every intersecting pair of the tree with its current radii, (smaller id, larger id), sorted.
// O(N) expected with a uniform grid over [lo, hi].
std::vector<std::pair<std::int32_t, std::int32_t>> intersectingPairs(const VascularTree& tree, const Vec3& lo, const Vec3& hi);

}  // namespace angiosynth
