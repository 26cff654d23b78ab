#pragma once
// VascuSynth's oxygen-demand-driven CCO (seed 002 §3.4–3.10), done right:
// - candidates at continuous positions, drawn ∝ current demand from a sum tree (O(log V));
// - the CLOSEST_NEIGHBOURS nearest segments from a uniform grid, each given its optimal
//   bifurcation for the whole-tree cost (BifurcationOptimizer, evaluated in parallel);
// - incremental updates along the path to the root on acceptance;
// - no connection that makes two vessel capsules intersect, judged with the radii the vessels are
//   predicted to have in the final tree (they thicken as terminals are added), and a final exact
//   check that removes and regrows the few branches that still collide.
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>

#include "core/vascular_tree.hpp"
#include "domain/demand_map.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

struct GrowthOptions {
  std::int64_t terminals = 1000;       // N
  Vec3 root_mm;                        // perforation point
  double min_distance_mm = 0;          // candidates closer than this to any segment are rejected
  int closest_neighbours = 5;          // segments tried per candidate
  double min_segment_length_mm = 0;    // no segment shorter than this (0: voxel/20)
  PhysicsParameters physics;           // total_terminals is set from `terminals`
  std::uint64_t seed = 1;
  std::uint64_t sample = 0;            // sample index within a dataset
  bool avoid_intersections = true;
  int max_repair_rounds = 30;
  // Give up after this many consecutive rejected candidates.
  std::int64_t max_consecutive_rejections = 200000;

  double minSegmentLength(double voxel_mm) const { return min_segment_length_mm > 0 ? min_segment_length_mm : voxel_mm / 20; }
};

struct GrowthReport {
  std::int64_t candidates = 0;             // candidate terminals drawn
  std::int64_t rejected_too_close = 0;     // within MIN_DISTANCE of the tree
  std::int64_t rejected_unreachable = 0;   // every trial connection crossed zero demand
  std::int64_t rejected_intersection = 0;  // every admissible connection made vessels intersect
  std::int64_t retracted_terminals = 0;    // terminals pulled back along their segment to clear a vessel
  std::int64_t moved_nodes = 0;            // nodes moved to separate two vessels
  std::int64_t repaired_terminals = 0;     // terminals removed and regrown by the final check
  int repair_rounds = 0;
  std::int64_t intersecting_pairs = 0;     // in the final tree (target 0)
  // CCO only.
  std::int64_t threshold_relaxations = 0;  // δ_max × 0.9 after a run of failed draws
  std::int64_t neighbour_doublings = 0;    // ν doubled because every candidate failed
  std::int64_t kamiya_failures = 0;        // Kamiya's iteration found no bifurcation
  std::int64_t short_segments = 0;         // final segments with length <= 2 r (target 0)
  std::int64_t outside_segments = 0;       // final segments leaving the domain (target 0)
  double root_radius_mm = 0;
};

using ProgressFn = std::function<void(std::int64_t done, std::int64_t total)>;

class GrowthError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Grows the tree; throws GrowthError when the domain cannot take N terminals.
VascularTree growVascuSynth(const DemandMap& map, const GrowthOptions& options, GrowthReport& report,
                            const ProgressFn& progress = {});

}  // namespace angiosynth
