#pragma once
// Checks, in milliseconds, that growth can succeed, so that a bad parameter set fails naming its
// cause instead of grinding: terminals that cannot lie apart, vessels too thick for the room.
#include <cstdint>
#include <string>

#include "physics/hemodynamics.hpp"

namespace angiosynth {

// Estimated radii of an N-terminal tree: a symmetric tree whose segments halve in flow and
// shrink by 2^(-1/γ) in radius and 2^(-1/d) in length per level, with the given pressure drop.
// It is close to grown CCO trees' root and terminal radii (docs/benchmarks.md, "Figures behind
// design choices"), close enough to refuse a file that cannot grow before any growth.
struct RadiusEstimate {
  double root = 0, terminal = 0, spacing = 0;
};
RadiusEstimate estimateRadii(const PhysicsParameters& p, std::int64_t terminals, double measure, int dim);

// Balls of diameter min_distance around the terminals cannot fill more than 74 % of space.
void checkPacking(std::int64_t terminals, double min_distance_mm, double measure_mm3, const std::string& file, int line);
// Terminal vessels must be thinner than a quarter of the spacing between terminals.
void checkVesselRoom(const PhysicsParameters& p, std::int64_t terminals, double measure, int dim, const std::string& file, int line);

}  // namespace angiosynth
