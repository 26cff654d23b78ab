#pragma once
// A bifurcation moved so that none of its segments is shorter than a given number of radii.
#include <cstdint>
#include <optional>

#include "core/vascular_tree.hpp"

namespace angiosynth {

// Where node v (not a root) would have each segment meeting there (its own and its children's)
// at least kSpreadLength × `min_ratio` radii long, found by pushing it away from the far end of
// each segment still shorter than kSpreadSettled × `min_ratio` radii, in a few sweeps. nullopt if
// no segment is short, or if the pushes do not settle within kSpreadLength × `min_ratio` radii
// of the thickest of them (the ends leave no room nearby: a farther move would reshape the
// bifurcation, not lengthen it). Near the root of an organ-scale tree a short trunk's sibling or
// child is often as short as the trunk: a slide along one segment shortens the other, and only a
// move away from all of them lengthens both.
std::optional<Vec3> spreadBifurcation(const VascularTree& tree, std::int32_t v, double min_ratio = 2);

// spreadBifurcation at each end of segment s in turn, its distal node then its proximal one
// (bifurcations only), each point handed to the grower's own checked move(v, q); true once one
// is taken.
template <class Move>
bool spreadEitherEnd(const VascularTree& tree, std::int32_t s, double min_ratio, Move&& move) {
  for (const auto v : {s, tree.parent[s]})
    if (v >= 0 && !tree.isRoot(v) && !tree.isTerminal(v))
      if (const auto q = spreadBifurcation(tree, v, min_ratio); q && move(v, *q)) return true;
  return false;
}

// The length, in minimum lengths, the pushes give a short segment...
inline constexpr double kSpreadLength = 1.05;
// ... and the length from which a segment counts as long enough (the growers' checks allow a
// margin of 1–2 % on the radius).
inline constexpr double kSpreadSettled = 1.025;

}  // namespace angiosynth
