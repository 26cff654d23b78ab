#pragma once
// What both surface-net meshers (net_surface.cpp on a uniform grid, vessel_surface.cpp's dual
// of the octree) do alike with a sheet's vertex and a crossed edge's quadrilateral.
#include <cmath>
#include <cstdint>

#include "mesh/vessel_surface.hpp"

namespace angiosynth {

// Quadrilateral q (counter-clockwise seen from outside) as two triangles, split along the
// diagonal that folds it least (the larger cosine between the halves' normals).
inline void appendQuad(SurfaceMesh& m, const std::int32_t (&q)[4]) {
  const auto P = [&](int k) -> const Vec3& { return m.vertices[std::size_t(q[k])]; };
  const auto fold = [&](int i) {
    const Vec3 n1 = cross(P((i + 1) % 4) - P(i), P((i + 2) % 4) - P(i)), n2 = cross(P((i + 2) % 4) - P(i), P((i + 3) % 4) - P(i));
    const double l = norm(n1) * norm(n2);
    return l > 0 ? dot(n1, n2) / l : -2.0;
  };
  const int i = fold(0) >= fold(1) ? 0 : 1;
  m.triangles.push_back({q[i], q[(i + 1) % 4], q[(i + 2) % 4]});
  m.triangles.push_back({q[i], q[(i + 2) % 4], q[(i + 3) % 4]});
}

// Three Newton steps from p towards the zero of `distance` (its gradient by central differences
// of `e`), each result passed through `keep` (a clamp to the vertex's cell); stops within
// `tolerance` or where the gradient vanishes.
template <class Distance, class Keep>
Vec3 ontoSurface(Vec3 p, const Distance& distance, double e, double tolerance, const Keep& keep) {
  p = keep(p);
  for (int it = 0; it < 3; ++it) {
    const double d = distance(p);
    if (!std::isfinite(d) || std::abs(d) < tolerance) break;
    const Vec3 g((distance(p + Vec3(e, 0, 0)) - distance(p - Vec3(e, 0, 0))) / (2 * e),
                 (distance(p + Vec3(0, e, 0)) - distance(p - Vec3(0, e, 0))) / (2 * e),
                 (distance(p + Vec3(0, 0, e)) - distance(p - Vec3(0, 0, e))) / (2 * e));
    const double g2 = dot(g, g);
    if (!std::isfinite(g2) || !(g2 > 1e-24)) break;
    p = keep(p - g * (d / g2));
  }
  return p;
}

}  // namespace angiosynth
