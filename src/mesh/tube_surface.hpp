#pragma once
// The outer surface of a vascular forest built along its vessels: where a vessel runs free (no
// other vessel near its wall), its surface is a tube of rings on its exact wall; where vessels
// meet (bifurcations, round ends, vessels that come close to another), the union of their
// capsules is contoured (vessel_surface.hpp), cut by a plane across each tube that leaves it, and
// joined to the tube's rings. Marching tetrahedra put isotropic triangles of the contour step
// everywhere; a tube needs a few dozen per radius of length, so long thin vessels, most of a
// grown tree, cost little: one closed surface per tree, of genus 0 where no vessels overlap.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/vascular_tree.hpp"
#include "mesh/decimate.hpp"
#include "mesh/vessel_ends.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth {

// Rings this many of their vertex spacings apart give acute triangles near equilateral (the rings
// are staggered), which TetGen's quality refinement (-q1.414) leaves unsplit; at 3 of them (two
// radii at 3 samples across) it adds a point per tube triangle.
constexpr double kCfdRingSpacing = 1.5;

struct TubeSurfaceOptions {
  SurfaceOptions junction;        // how the meeting parts are contoured (samples across, volume)
  double ring_spacing_radii = 8;  // tube rings at most this many radii apart, aligned; 0: kCfdRingSpacing times the ring's vertex spacing, staggered
  int min_ring_vertices = 8;      // and at least this many around
  int ring_vertices = 0;          // that many around (0: π × junction samples across, at least min_ring_vertices)
  double ring_tolerance_mm = 0;   // and more where a ring's chords would stand further than this inside the wall
  std::vector<VesselEnd> ends;    // CFD ends (openEnds): each cut by its plane; empty: round ends
  bool cap_ends = false;          // fill each end's loop with a planar cap (else left open)
  bool decimate = false;          // decimate each contoured part (its cut loops stay)
  bool nets = true;               // contour parts by surface nets where they pass their checks (net_surface.hpp)
  bool remesh = false;            // remesh each contoured part isotropically to its step (its cut loops stay; not with decimate)
  DecimateOptions decimation;
};

struct TubeSurfaceReport {
  std::int64_t vessels = 0, tubes = 0, clusters = 0;  // vessels with a tube; contoured parts
  std::int64_t largest_cluster_vessels = 0;
  std::int64_t contour_triangles = 0, tube_triangles = 0;
  // Triangles marching tetrahedra made, with the prolongations past the cuts (cut away) and the
  // contours made again (finer, or with cuts moved) of the parts kept: the contouring's work.
  std::int64_t contoured_triangles = 0;
  std::int64_t netted = 0;       // parts contoured by surface nets (the others by marching tetrahedra)
  std::int64_t fallbacks = 0;    // tubes given up because their cut failed (their vessel contoured whole)
  std::int64_t cut_retries = 0;  // parts contoured again with a failed cut further into its tube
  std::int64_t refinements = 0;  // parts contoured again, finer, to lose a handle a tree's union does not have
  std::int64_t rounds = 0;       // meshing rounds (each after tubes were given up)
  std::int64_t largest_remeshed = 0;
  double estimated_bytes = 0, finest_step_mm = 0;
  std::int64_t cavities_removed = 0;
  std::int64_t triangles_before_decimation = 0, decimation_collapses = 0;
  std::int64_t slivers_repaired = 0;                   // collapses, flips and moves that repaired the contour's slivers
  std::int64_t remesh_splits = 0, remesh_changes = 0;  // the remeshing's splits, and all its changes
  double decimation_largest_error_mm = 0;
  EndCutReport ends;  // per options.ends
};

// Throws InputError (no file) when a part's grid would exceed the memory limit.
SurfaceMesh tubeSurface(const VascularTree& forest, const TubeSurfaceOptions& options, TubeSurfaceReport* report = nullptr,
                        const std::function<void(std::int64_t done, std::int64_t total)>& progress = {});

}  // namespace angiosynth
