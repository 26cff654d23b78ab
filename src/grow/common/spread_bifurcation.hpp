#pragma once
// A bifurcation moved so that none of its segments is shorter than twice its radius.
#include <cstdint>
#include <optional>

#include "core/vascular_tree.hpp"

namespace angiosynth {

// Where node v (not a root) would have each segment meeting there (its own and its children's)
// at least kSpreadLength radii long, found by pushing it away from the far end of each segment
// still shorter than kSpreadSettled radii, in a few sweeps. nullopt if no segment is short, or
// if the pushes do not settle within kSpreadLength radii of the thickest of them (the ends leave
// no room nearby: a farther move would reshape the bifurcation, not lengthen it). Near the root of an organ-scale tree a
// short trunk's sibling or child is often as short as the trunk: a slide along one segment
// shortens the other, and only a move away from all of them lengthens both.
std::optional<Vec3> spreadBifurcation(const VascularTree& tree, std::int32_t v);

// The length, in radii, the pushes give a short segment...
inline constexpr double kSpreadLength = 2.1;
// ... and the length from which a segment counts as long enough (the growers' checks ask for
// more than 2.04 r: 2 r with a 2 % margin on the radius).
inline constexpr double kSpreadSettled = 2.05;

}  // namespace angiosynth
