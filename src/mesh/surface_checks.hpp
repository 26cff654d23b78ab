#pragma once
// Checks of a closed triangle surface for what a contour that is not safe by construction (dual
// contouring, net_surface.hpp) may get wrong.
#include <cstdint>
#include <vector>

#include "mesh/vessel_surface.hpp"

namespace angiosynth {

// Every vertex's triangles form one fan closed around it, each edge used once each way (so:
// closed, manifold at edges and vertices, consistently oriented), and no triangle is degenerate.
bool closedManifold(const SurfaceMesh& m);

// No two triangles cross or overlap beyond what they share: each pair whose boxes meet in the
// bins of `cell` (mm, from `origin`) is tested with orientation predicates (touching counts).
bool freeOfCrossings(const SurfaceMesh& m, const Vec3& origin, double cell);
// The triangles of such pairs, in order (only the first pair's with first_only); with `dirty`
// (a flag per triangle), only of pairs with a dirty triangle: after moving some vertices, the
// triangles at them and those that crossed before are dirty, and the rest's pairs stand.
std::vector<std::int32_t> crossingTriangles(const SurfaceMesh& m, const Vec3& origin, double cell, bool first_only = false,
                                            const std::vector<char>* dirty = nullptr);

}  // namespace angiosynth
