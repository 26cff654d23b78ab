#pragma once
// The outer surface of a vascular forest as a triangle mesh, one closed surface per tree: the
// zero set of the signed distance to the union of the tree's vessels (capsules and round cones,
// the solids the labels rasterise) sampled on an adaptive grid and contoured by marching
// tetrahedra. Each vessel is sampled at its own step (cells of 2^l finest steps, the coarsest
// that keep samples_across samples across it), in the cells near its surface only; the cells
// form a 2:1-balanced octree split into conforming tetrahedra (balanced_octree.hpp), so the
// surface of the piecewise-linear distance is closed, manifold and free of self-intersections
// by construction; vertices lie on the vessels' surface and are welded by the edge they lie on.
// Units of cells are meshed in parallel, and the mesh does not depend on the thread count.
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/vascular_tree.hpp"
#include "mesh/surface_mesh.hpp"

namespace angiosynth {

// Cells grow up to 2^kMaxSurfaceLevel finest steps.
constexpr int kMaxSurfaceLevel = 10;
// A gap between two vessels is contoured with cells of a third of its width: the fillet stays
// inside it and no tetrahedron spans it.
constexpr double kGapCells = 3;

struct SurfaceOptions {
  double voxel_mm = 0;     // finest grid step; 0: the thinnest vessel's diameter / samples_across
  int samples_across = 4;  // samples across each vessel's thinnest end (at least)
  double max_cell_mm = 0;  // and cells no larger than this (0: no bound; a hollow wall's thickness)
  // Per segment id of the tree given (empty, or 0 for none): cells around that vessel no larger
  // than this (two vessels that come close without touching: cells that resolve their gap).
  std::vector<double> vessel_max_cell_mm;
  // Per segment id (empty, or none): the vessels across its gap. Its cells are then that fine
  // only near them: a cell of its own level or finer stays no larger than 1/kGapCells of its
  // distance to their surface, so the cells grade down to the gap where it is thinnest.
  std::vector<std::vector<std::int32_t>> vessel_gap_partners;
  bool adaptive = true;  // false: every vessel at the finest step
  // Move vertices off the surface by ¾ of their triangles' mean gap (a fraction of the chords'
  // sagitta) so the enclosed volume is the vessels'; false: every vertex on the surface.
  bool restore_volume = true;
  // Contour by surface nets on the octree (the dual of the cells: about a third of the triangles)
  // where the result is a closed manifold free of self-intersections; else marching tetrahedra.
  bool dual = false;
  std::uint64_t memory_limit = 0;  // bytes; 0: no limit
  // Called on the finished mesh while the exact signed distance to each tree's surface is at
  // hand (distance(tree, p), mm): cutting ends, decimation.
  std::function<void(SurfaceMesh&, const std::function<double(std::int32_t, const Vec3&)>&)> finish;
};

struct SurfaceReport {
  double voxel_mm = 0;     // the finest step
  double coarsest_mm = 0;  // the coarsest cell
  int levels = 0;
  std::int64_t cells = 0, units = 0;
  double estimated_bytes = 0;
  std::int64_t cavities_removed = 0;
  double largest_volume_move_mm = 0;   // closed pockets of outside space below the grid's resolution
  bool dual = false;                   // contoured by surface nets (options.dual and its checks passed)
  const char* dual_refused = nullptr;  // options.dual, but marching tetrahedra: why
};

// Throws InputError (no file) when the grid would exceed the memory limit or the index range.
SurfaceMesh vesselSurface(const VascularTree& forest, const SurfaceOptions& options, SurfaceReport* report = nullptr,
                          const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

// Flat triangles through points of a convex wall are chords and lose volume: each vertex moves
// out along its normal by ¾ of its triangles' area-weighted gap at their centroids (by `distance`,
// at most a fifth of its vertex_step), for meshes whose vertices lie on no grid edge (surface
// nets). Returns the largest move (mm).
double restoreVolumeAlongNormals(SurfaceMesh& m, const std::function<double(std::int32_t, const Vec3&)>& distance);

// Keeps the triangles flagged in `keep` (with their tree and face labels) and the vertices they
// use, both in their order; `renumber`: old vertex → new (−1 for dropped).
void keepTriangles(SurfaceMesh& m, const std::vector<char>& keep, std::vector<std::int32_t>* renumber = nullptr);

// Drops the closed components whose box is under a quarter of their finest vertex step across
// (the union has no feature that small: every vessel is sampled at least once across): what
// untangling leaves of a knot, its vertices drawn onto one point. Returns how many.
std::int64_t removeSpecks(SurfaceMesh& m);

// The area of m's triangle t (mm²).
inline double triangleArea(const SurfaceMesh& m, const std::array<std::int32_t, 3>& t) {
  const Vec3& a = m.vertices[std::size_t(t[0])];
  return 0.5 * norm(cross(m.vertices[std::size_t(t[1])] - a, m.vertices[std::size_t(t[2])] - a));
}

// The mesh's own account of itself (the tests judge written files with VTK): edges used once
// (boundary) or more than twice, edges both triangles run the same way (inconsistent
// orientation), triangles with a repeated vertex, and the enclosed volume (divergence theorem).
struct MeshTopology {
  std::int64_t boundary_edges = 0, nonmanifold_edges = 0, misoriented_edges = 0, degenerate_triangles = 0;
  double volume_mm3 = 0;
  // Per tree (forest index; trees without triangles have 0 components): connected surfaces and
  // the Euler characteristic V − E + F (2 per sphere-like surface; each handle takes 2).
  std::vector<std::int64_t> tree_components, tree_euler;
};
MeshTopology meshTopology(const SurfaceMesh& mesh);

}  // namespace angiosynth
