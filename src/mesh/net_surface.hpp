#pragma once
// The surface of a small part of a tree (a junction and the stubs of its vessels, all of like
// radius) by dual contouring on a uniform grid ("surface nets"): a vertex on the surface for
// each sheet the surface passes through a cell with (cells' sheets told apart by the faces'
// asymptotic decider, as marching cubes does), a quadrilateral around each grid edge it crosses.
// That is about 2.5 triangles per step² of surface against marching tetrahedra's 8 (more where
// their cells change size), at the same step. Unlike marching tetrahedra it is not manifold and free of self-intersections by
// construction: the mesh is checked for both and not returned when it fails, so the caller
// contours the part with vesselSurface instead.
#include <optional>

#include "mesh/vessel_surface.hpp"

namespace angiosynth {

struct NetReport {
  const char* refused = nullptr;  // why no mesh was returned (nullptr: it was)
  bool costlier = false;          // refused because the part's radii lie too far apart for one step
};

// The distance, step and fillets are vesselSurface's at its finest level for the same options;
// options.finish is called on a mesh that passed the checks. Parts with gaps to resolve
// (vessel_max_cell_mm), several trees, more than kNetMaxVessels vessels or kNetMaxPoints grid
// points, and those marching tetrahedra would give fewer triangles (their vessels' radii far
// apart) are refused. Triangles per step² of surface, measured on grown trees:
constexpr double kNetTriangles = 2.5, kTetTriangles = 8;
constexpr std::size_t kNetMaxVessels = 64;
constexpr std::int64_t kNetMaxPoints = std::int64_t(1) << 21;
std::optional<SurfaceMesh> netSurface(const VascularTree& part, const SurfaceOptions& options, SurfaceReport* report = nullptr,
                                      NetReport* net = nullptr);

}  // namespace angiosynth
