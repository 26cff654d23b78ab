#pragma once
// A closed surface clipped to an axis-aligned box: the block a print is cut to (Lázaro 2011
// intersects its hollow vessels with their bounding box to open them). Each side of the box in
// turn cuts the triangles that cross its plane, drops what lies outside, and fills the section
// of the solid in that plane: the polygons the cut loops bound, with their holes (a hollow
// wall's lumen stays open where the side crosses it). The section is a constrained Delaunay
// triangulation of the loops' own vertices, so the surface stays closed and welded.
#include <array>
#include <cstdint>

#include "mesh/vessel_surface.hpp"

namespace angiosynth {

inline constexpr const char* kBoxSideNames[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};

struct BoxClipReport {
  // Per side (−x, +x, −y, +y, −z, +z): the section's triangles, area (mm²) and boundary loops.
  std::array<std::int64_t, 6> section_triangles{};
  std::array<double, 6> section_area_mm2{};
  std::array<std::int64_t, 6> section_loops{};
  std::int64_t removed_triangles = 0;  // wholly outside the box
};

// Clips the closed surface m to the box [lo, hi] (mm). The section of side k gets face label
// first_face + k (m.triangle_face is filled with 0 where it was empty). Throws std::runtime_error
// if m is not closed where a side cuts it, or if a section's loops cross.
BoxClipReport clipToBox(SurfaceMesh& m, const Vec3& lo, const Vec3& hi, std::int32_t first_face);

}  // namespace angiosynth
