#pragma once
// The signed distance the surface meshers contour: the union of a tree's vessels (capsules and
// round cones) with a fillet where two of them face each other across a gap thinner than a step.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "raster/vessel_capsule.hpp"

namespace angiosynth {

// A vessel as the contour sees it: its solid, and the width k of the fillet it gets where it
// meets another (kFillet of its cell).
struct Solid {
  Capsule c;
  double k;
  Vec3 centre;  // a ball that holds the solid: its distance bounds the solid's from below
  double bound = 0;
  Solid() = default;
  Solid(const Capsule& capsule, double fillet) : c(capsule), k(fillet), centre(capsule.a + capsule.d * 0.5) {
    bound = 0.5 * norm(capsule.d) + capsule.r;
  }
  // The direction away from the solid at p (from the nearest point of its axis).
  Vec3 away(const Vec3& p) const {
    const double t = c.inv_len2 > 0 ? std::clamp(dot(p - c.a, c.d) * c.inv_len2, 0.0, 1.0) : 0.0;
    const Vec3 off = p - (c.a + c.d * t);
    const double len = norm(off);
    return len > 0 ? off / len : Vec3(0, 0, 0);
  }
};
constexpr double kFillet = 2.0;

// Signed distance to the union of the solids (+∞ for none), with a fillet where two vessels
// face each other across a thin gap: where they part at a shallow angle, the gap is thinner than
// a step over some length, and a plain minimum sampled on the grid bridges it in separate
// places, each a handle the union does not have. There the smooth minimum min(a, b) − h²k/4
// (h = 1 − |a − b|/k where positive, k the finest fillet of the vessels there) closes it in one piece; k
// is full where the two surfaces' normals are more than 143° apart (they face each other across
// a gap) and fades to nothing at 107° (the creases of every junction keep their volume). The
// fillet stands at most k/4 off the union, outside it. The order of the solids is fixed, so
// every unit gets the same value.
inline double unionDistance(const std::vector<Solid>& solids, const Vec3& p, double* plain = nullptr) {
  double best = std::numeric_limits<double>::infinity(), k_min = std::numeric_limits<double>::infinity();
  if (plain) *plain = std::numeric_limits<double>::infinity();
  for (const auto& s : solids) k_min = std::min(k_min, s.k);
  // The solid nearest so far, and its direction at p once a fillet needed it.
  const Solid* nearest = nullptr;
  Vec3 n_best(0, 0, 0);
  bool have_n_best = false;
  for (const auto& s : solids) {
    // A solid whose ball lies k_min beyond the best neither lowers it nor fillets it (h = 0
    // below): skipped, unless the plain minimum is asked for as well.
    if (!plain && nearest) {
      const Vec3 q = p - s.centre;
      const double reach = best + k_min + s.bound * (1 + 1e-9);
      if (reach > 0 && dot(q, q) >= reach * reach) continue;
    }
    const double d = s.c.depth(p);
    if (plain) *plain = std::min(*plain, d);
    if (!nearest) {
      best = d, nearest = &s;
      continue;
    }
    // Only where the two are within k_min of each other can the fillet (k ≤ k_min) act.
    const double gap = std::abs(best - d);
    double h = 0, k = 0;
    Vec3 n(0, 0, 0);
    const bool near = gap < k_min;
    if (near) {
      n = s.away(p);
      if (!have_n_best) n_best = nearest->away(p), have_n_best = true;
      const double facing = std::clamp((-dot(n, n_best) - 0.3) * 2, 0.0, 1.0);
      k = k_min * facing, h = k > 0 ? std::max(0.0, 1 - gap / k) : 0.0;
    }
    if (d < best) nearest = &s, n_best = n, have_n_best = near;
    best = std::min(best, d) - h * h * k / 4;
  }
  return best;
}

// What changes the surface after contouring (decimation, sliver repair) measures its error from
// the union and the fillets alike (the larger), so that a fillet's offset never adds to it.
inline double strictDistance(const std::vector<Solid>& solids, const Vec3& p) {
  double plain = 0;
  const double filleted = unionDistance(solids, p, &plain);
  return std::abs(plain) > std::abs(filleted) ? plain : filleted;
}

}  // namespace angiosynth
