#pragma once
// DCCO's candidate bifurcation points and angle limits (Maso Talou et al. 2021 §1.1.4, §1.1.9–1.1.10).
#include <vector>

#include "core/vec3.hpp"
#include "core/vessel_roles.hpp"

namespace angiosynth {

// The points tried on vessel xp–xd for a new terminal xt:
// - versatile: the triangle (xt, xp, xd) on a lattice of Δv points per edge without its three
//   corners, Δv(Δv + 1)/2 − 3 points (25 at Δv = 7, 18 at Δv = 6);
// - fixed: the Δv − 2 inner points of the lattice edge xp–xd (the vessel's own line);
// - distal: xd alone (the branch leaves the vessel's end);
// - none (or unset): no point.
std::vector<Vec3> bifurcationLattice(const Vec3& xt, const Vec3& xp, const Vec3& xd, int delta_v, Branching b);

// θ (eq. 17), degrees: between the distal part b→xd of the split vessel and the new vessel b→xt.
double bifurcationAngle(const Vec3& b, const Vec3& xd, const Vec3& xt);
// φ (eq. 18 with the corrected normal n = (b − xp) × (xd − b)), degrees: between the new vessel
// b→xt and the plane of the split vessel's two parts. When the parts are collinear (b on the
// vessel's line) that plane is undefined and `fallback_normal` (the normal of the bifurcation the
// vessel leaves, zero for none) stands in; with neither, φ is 90° (no plane to stay near).
double openingAngle(const Vec3& xp, const Vec3& b, const Vec3& xd, const Vec3& xt, const Vec3& fallback_normal);

}  // namespace angiosynth
