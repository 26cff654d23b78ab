#pragma once
// The part of a triangle on the near side (s ≤ 0) of a plane, as triangles: its vertices there
// and the cut points of its crossing edges, a quad split along its shorter diagonal. Shared by
// the cuts at vessel ends and at the sides of a clip box.
#include <algorithm>
#include <array>
#include <cstdint>

#include "core/vec3.hpp"

namespace angiosynth {

// side(v): vertex v's signed distance to the plane; cut(a, b): the vertex where edge a–b crosses
// it; at(v): a vertex's position; emit(a, b, c): one triangle, turned as `tri`.
template <class Side, class Cut, class At, class Emit>
void clipTriangleToPlane(const std::array<std::int32_t, 3>& tri, Side&& side, Cut&& cut, At&& at, Emit&& emit) {
  std::int32_t poly[4];
  int n = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto a = tri[i], b = tri[(i + 1) % 3];
    const double sa = side(a), sb = side(b);
    if (sa <= 0) poly[n++] = a;
    if ((sa < 0 && sb > 0) || (sa > 0 && sb < 0)) poly[n++] = cut(a, b);
  }
  if (n == 4 && distance(at(poly[1]), at(poly[3])) < distance(at(poly[0]), at(poly[2]))) std::rotate(poly, poly + 1, poly + 4);
  for (int i = 1; i + 1 < n; ++i) emit(poly[0], poly[i], poly[i + 1]);
}

}  // namespace angiosynth
