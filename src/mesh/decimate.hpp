#pragma once
// Edge-collapse decimation of a vessel surface (Garland–Heckbert quadrics), with the checks that
// keep it a valid surface of the vessels: the link condition (no change of topology), no
// triangle turned by more than a bound, no new angle below a floor (or below the smallest it
// replaces), and every new vertex and new triangle's centroid within a share of its local step
// of the vessels' exact surface (the distance the mesher contoured). Marching tetrahedra put
// isotropic triangles of the cell size everywhere; along straight vessels long triangles do as
// well, so most of them go. Blocks of space are decimated in parallel, each in the order (cost,
// vertex ids) and only where all it reads lies inside it, so the result does not depend on the
// thread count.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "mesh/vessel_surface.hpp"

namespace angiosynth {

struct DecimateOptions {
  double max_error = 0.1;     // share of the local step: largest distance of a new vertex or centroid from the surface
  double min_angle_deg = 15;  // a new triangle's angles stay above this (or above the smallest they replace)
  double max_turn_deg = 45;   // largest turn of a triangle's normal by one collapse
  double sliver_deg = 10;     // a triangle with an angle below this is repaired where the checks allow (0: none)
  double obtuse_deg = 0;      // with sliver_deg: then a triangle with an angle above this is improved where the checks allow (0: none)
};

struct DecimateReport {
  std::int64_t before = 0, after = 0, collapses = 0, flips = 0, moves = 0, splits = 0;
  double largest_error_mm = 0;  // largest |distance| of a vertex placed

  std::int64_t changes() const { return collapses + flips + moves + splits; }
  // Another pass over the same mesh: its changes added, its count of triangles the last.
  DecimateReport& operator+=(const DecimateReport& o) {
    after = o.after, collapses += o.collapses, flips += o.flips, moves += o.moves, splits += o.splits;
    largest_error_mm = std::max(largest_error_mm, o.largest_error_mm);
    return *this;
  }
};

// `distance(tree, p)`: signed distance (mm, negative inside) from p to the surface of tree
// `tree`. Vertices of cap faces (triangle_face ≠ 0) and of boundary loops do not move (and
// boundary loops keep their vertices in order). Vertices the collapses remove are dropped (the
// others keep their order; `renumber`: old vertex → new, −1 for dropped).
DecimateReport decimate(SurfaceMesh& m, const DecimateOptions& o, const std::function<double(std::int32_t, const Vec3&)>& distance,
                        std::vector<std::int32_t>* renumber = nullptr);

// Remeshing's defaults: edges of this many steps (triangles of the nets' quads' area: a net's
// vertex stands for a square of its step, an equilateral triangle's for √3/2 of its edge
// squared), in this many rounds.
constexpr double kRemeshTarget = 1.07;
constexpr int kRemeshRounds = 5;

// Isotropic remeshing (Botsch and Kobbelt 2004) of the wall's free vertices, `rounds` times:
// edges longer than 4/3 of `target` × their ends' step split, shorter than 4/5 collapse, flips
// that raise the smallest angle and flips towards valence 6, vertices moved towards their
// neighbours' mean where that betters the worst triangle around them; every change under the
// checks of decimation; then (o.sliver_deg) the slivers' and obtuse triangles' repair. The
// surface nets' quads make pairs of right-angled triangles whose corners lie on each other's
// circumsphere: TetGen's quality refinement splits nearly all of them, and every split costs it
// a traversal of its queues. Boundary loops keep their order, their short edges collapsing into
// the survivor, which stays. One worker (a contoured part at a time; the caller runs parts in
// parallel). Appends the new vertices; `renumber` as for decimate (−1 for a loop's vertex that
// went too).
DecimateReport remeshIsotropic(SurfaceMesh& m, const DecimateOptions& o, double target, int rounds,
                               const std::function<double(std::int32_t, const Vec3&)>& distance, std::vector<std::int32_t>* renumber = nullptr);

// Slivers only (a triangle with an angle below o.sliver_deg), under the checks of decimation: an
// edge collapses (the shortest first), else a cap's longest edge flips, else a corner moves to
// the middle of its neighbours on the surface. Marching tetrahedra leave them where the surface
// passes near a grid point, and a tetrahedral mesher refines around each. `at_fixed_only`: only
// slivers with a fixed vertex (a cap's or a boundary loop's: what a cut made).
DecimateReport repairSlivers(SurfaceMesh& m, const DecimateOptions& o, const std::function<double(std::int32_t, const Vec3&)>& distance,
                             std::vector<std::int32_t>* renumber = nullptr, bool at_fixed_only = false);

}  // namespace angiosynth
