#pragma once
// Rings and loops on vessel surfaces, shared by the tube mesher and the hollow wall: the
// boundary loops in cut planes, and the band of triangles between two rings around one axis
// (along a tube, or across the end of a wall).
#include <array>
#include <cstdint>
#include <vector>

#include "mesh/vessel_ends.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth {

// The boundary loops of a mesh: directed edges used once, chained (a chain that branches or
// breaks off is left out). Cut loops lie in planes: only edges between vertices `on` flags can
// be on them (every triangle holding such an edge is looked at, so the count is exact).
std::vector<std::vector<std::int32_t>> boundaryLoops(const SurfaceMesh& m, const std::vector<char>& on);

// The vertices in one of the ends' planes (cuts put them there exactly), within 2 radii of its
// centre.
std::vector<char> verticesInPlanes(const SurfaceMesh& m, const std::vector<VesselEnd>& planes);

// Each plane's boundary loop in m, counter-clockwise around the plane's normal and star-shaped
// around its centre, or empty where there is none, `skip` says so, or it cannot be made so. A
// cut loop may step back by a hair where two of its vertices sit at one angle (a cut point next
// to a vertex the volume restoration slid); such an edge, at most a twentieth of the radius
// long, is collapsed into its first vertex when that keeps the surface a manifold and turns no
// triangle over (else into its second, where that does); so is (where it can be) an edge so short that single-precision formats would
// round its ends onto one point. m loses the triangles the collapses removed (and the vertices only they used);
// the loops are numbered after that.
// `bent`, if given, gets the loops that stay bent (counter-clockwise, else empty).
std::vector<std::vector<std::int32_t>> starLoops(SurfaceMesh& m, const std::vector<VesselEnd>& planes, const std::vector<char>& skip = {},
                                                 std::vector<std::vector<std::int32_t>>* bent = nullptr);

// Ear clipping of a simple polygon counter-clockwise in the plane (u, w): triangles as indices
// into it, or empty if it is not simple enough to clip.
std::vector<std::array<int, 3>> earClip(const std::vector<Vec3>& polygon, const Vec3& u, const Vec3& w);

// e1 ⟂ u, and e2 = u × e1: (e1, e2, u) is right-handed.
void frameOf(const Vec3& u, Vec3& e1, Vec3& e2);

// Triangles between ring A and ring B, both counter-clockwise around the axis through c along u
// and star-shaped around it: A nearer −u (or, in one plane, the outer one), B the other. From
// the vertex of each at the smallest angle, always advancing on the ring whose next vertex comes
// first around the axis; the triangles face away from the axis (in one plane: along u). Each
// gets `tree` and `face`. `by_shape`: at each step the triangle whose largest angle is the
// smaller (a contoured loop's irregular spacing makes obtuse triangles by the angles' order).
void zipRings(SurfaceMesh& m, const Vec3& c, const Vec3& u, const std::vector<std::int32_t>& A, const std::vector<std::int32_t>& B, std::int32_t tree,
              std::int32_t face = 0, bool by_shape = false);

}  // namespace angiosynth
