#pragma once
// Trees drawn as chains of short segments (space colonisation, L-system stems): their overlap
// check, which must not count a chain touching itself, and their flows and pressures when every
// leaf takes an equal share of the inflow.
#include <cstdint>
#include <utility>
#include <vector>

#include "core/vascular_tree.hpp"
#include "domain/growth_domain.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

// The domain's diameter (a mask's largest extent): lengths not given in mm are fractions of it.
double diameterOf(const GrowthDomain& d);

// Flows (each leaf an equal share of Q) and pressures (Poiseuille from the root pressure) of a
// tree whose radii are set; lengths, depth, β and terminal counts too.
void flowsAndPressures(VascularTree& t, const PhysicsParameters& p, double leaf_flow);

// Overlapping capsules, except segments of one tree joined by a path shorter than their radii
// (chains of short segments in a thick vessel touch by construction); (smaller, larger) ids, sorted.
std::vector<std::pair<std::int32_t, std::int32_t>> crossingPairs(const VascularTree& t);

}  // namespace angiosynth
