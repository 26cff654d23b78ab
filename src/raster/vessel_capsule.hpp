#pragma once
// One vessel segment as a solid: a capsule (cylinder with spherical caps), or for a tapered
// vessel a round cone (the convex hull of a sphere of radius ra at a and one of rb at b); with
// its signed distance. Shared by the rasteriser and the surface mesher, so labels and meshes
// describe the same solid.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/vascular_tree.hpp"

namespace angiosynth {

// Positions in mm (so distances are in mm).
struct Capsule {
  Vec3 a, d;             // start and axis (mm)
  double inv_len2 = 0;   // 1/|d|²
  double r = 0, r2 = 0;  // the cylinder's radius; a cone's larger one
  std::uint32_t id = 0;
  bool cone = false;
  Vec3 e;                                                // unit axis
  double ra = 0, rb = 0, len = 0, sin_a = 0, cos_a = 1;  // sin α = (ra − rb)/len: the side's slope
  bool nested = false;                                   // |ra − rb| ≥ len: one sphere holds the other, no side
  // Signed distance to the surface, moved inwards by half_var·κ (κ: the mean curvature ×2 of
  // the nearest surface part: 1/r on a cylinder, cos α/ρ on a cone's side, 2/r on the caps).
  double signedDistance(const Vec3& p, double half_var) const {
    if (cone) return coneDistance(p, half_var);
    const Vec3 ap = p - a;
    const double u = inv_len2 > 0 ? dot(ap, d) * inv_len2 : 0.0;
    const double t = u < 0 ? 0 : (u > 1 ? 1 : u);
    const Vec3 q = ap - d * t;
    const double kappa = (t == u && inv_len2 > 0) ? 1.0 / r : 2.0 / r;
    return std::sqrt(dot(q, q)) - r + half_var * kappa;
  }
  // Unshifted signed distance (< 0 inside).
  double depth(const Vec3& p) const { return cone ? coneDistance(p, 0) : std::sqrt(dist2(p)) - r; }
  double dist2(const Vec3& p) const {
    const Vec3 ap = p - a;
    double t = inv_len2 > 0 ? dot(ap, d) * inv_len2 : 0.0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const Vec3 q = ap - d * t;
    return dot(q, q);
  }
  double coneDistance(const Vec3& p, double half_var) const {
    const Vec3 ap = p - a, bp = ap - d;
    const double da = std::sqrt(dot(ap, ap)) - ra, db = std::sqrt(dot(bp, bp)) - rb;
    if (nested) return da < db ? da + half_var * 2 / ra : db + half_var * 2 / rb;
    // In the plane of the axis and p: y along the axis, x from it. The side is the line tangent
    // to both circles; s is the position along it from the tangent point on sphere a.
    const double y = dot(ap, e), x = std::sqrt(std::max(0.0, dot(ap, ap) - y * y));
    const double s = y * cos_a - x * sin_a;
    if (s <= 0) return da + half_var * 2 / ra;
    if (s >= len * cos_a) return db + half_var * 2 / rb;
    const double rho = ra * cos_a - s * sin_a;  // the side's distance from the axis there
    return y * sin_a + x * cos_a - ra + half_var * cos_a / rho;
  }
};

inline Capsule capsuleOf(const VascularTree& t, std::int32_t s) {
  const Vec3 a = t.position[t.parent[s]], b = t.position[s];
  const Vec3 d = b - a;
  const double l2 = dot(d, d);
  const double r = t.maxRadius(s);
  Capsule c;
  c.a = a;
  c.d = d;
  c.inv_len2 = l2 > 0 ? 1.0 / l2 : 0.0;
  c.r = r;
  c.r2 = r * r;
  c.id = static_cast<std::uint32_t>(s);
  const double ra = t.startRadius(s), rb = t.radius[s];
  if (ra != rb) {
    c.cone = true;
    c.ra = ra;
    c.rb = rb;
    c.len = std::sqrt(l2);
    c.nested = std::abs(ra - rb) >= c.len;
    if (!c.nested) {
      c.e = d / c.len;
      c.sin_a = (ra - rb) / c.len;
      c.cos_a = std::sqrt(1 - c.sin_a * c.sin_a);
    }
  }
  return c;
}

}  // namespace angiosynth
