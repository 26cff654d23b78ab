#pragma once
// The outer surface of a vascular forest as a triangle mesh, one closed surface per tree: the
// zero set of the signed distance to the union of the tree's vessels (capsules and round cones,
// the solids the labels rasterise) sampled on a grid and contoured by marching tetrahedra.
// The grid's cubes are split into six tetrahedra along their main diagonal (Freudenthal), so
// neighbouring tetrahedra share faces and the surface of the piecewise-linear distance is closed,
// manifold and free of self-intersections by construction; vertices are welded by the grid edge
// they lie on. Only the 8³ bricks near a vessel surface are visited (in parallel), and the mesh
// does not depend on the thread count.
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/vascular_tree.hpp"

namespace angiosynth {

struct SurfaceMesh {
  std::vector<Vec3> vertices;                          // mm
  std::vector<std::array<std::int32_t, 3>> triangles;  // counter-clockwise seen from outside
  std::vector<std::int32_t> triangle_tree;             // the tree (forest index) of each triangle
};

struct SurfaceOptions {
  double voxel_mm = 0;         // grid step; 0: the thinnest vessel's diameter / samples_across
  int samples_across = 4;      // samples across the thinnest vessel when the step is automatic
  std::uint64_t memory_limit = 0;  // bytes; 0: no limit
};

struct SurfaceReport {
  double voxel_mm = 0;
  std::int64_t bricks = 0;
  double estimated_bytes = 0;
  std::int64_t cavities_removed = 0;  // closed pockets of outside space below the grid's resolution
};

// Throws InputError (no file) when the grid would exceed the memory limit or the index range.
SurfaceMesh vesselSurface(const VascularTree& forest, const SurfaceOptions& options, SurfaceReport* report = nullptr,
                          const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

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
