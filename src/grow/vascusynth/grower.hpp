#pragma once
// VascuSynth's oxygen-demand-driven CCO (Hamarneh & Jassi 2010 §3.4–3.10), done right:
// - candidates at continuous positions, drawn ∝ current demand from a sum tree (O(log V));
// - the CLOSEST_NEIGHBOURS nearest segments from a uniform grid, each given its optimal
//   bifurcation for the whole-tree cost (BifurcationOptimizer, evaluated in parallel);
// - incremental updates along the path to the root on acceptance;
// - no connection that makes two vessel capsules intersect, judged with the radii the vessels are
//   predicted to have in the final tree (they thicken as terminals are added), and a final exact
//   check that removes and regrows the few branches that still collide;
// - no segment shorter than min_length_ratio × its radius (CCO's l > 2r), so that no bifurcation
//   collapses into a disguised multifurcation (VascuSynth leaves such stubs where bifurcations merge).
#include <optional>
#include <string>
#include <cstdint>

#include "core/vascular_tree.hpp"
#include "domain/demand_map.hpp"
#include "grow/common/growth_report.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

struct GrowthOptions {
  std::int64_t terminals = 1000;                // N
  Vec3 root_mm;                                 // perforation point
  double min_distance_mm = 0;                   // candidates closer than this to any segment are rejected
  int closest_neighbours = 5;                   // segments tried per candidate
  std::optional<double> min_segment_length_mm;  // no segment shorter than this (unset: voxel/20)
  double min_length_ratio = 2;                  // no segment shorter than this × its radius (0: VascuSynth's rule, none)
  int relax_sweeps = 4;                         // final sweeps moving each bifurcation to its optimum for the final radii
  PhysicsParameters physics;                    // total_terminals is set from `terminals`
  std::uint64_t seed = 1;
  std::uint64_t sample = 0;  // sample index within a dataset
  bool avoid_intersections = true;
  // "vascusynth": VascuSynth's own constraints (Hamarneh & Jassi 2010), to reproduce its trees'
  // statistics: no minimum length in radii, no final relaxation, vessels allowed to overlap.
  std::string rules = "angiosynth";
  int max_repair_rounds = 30;
  // Give up after this many consecutive rejected candidates.
  std::int64_t max_consecutive_rejections = 200000;

  double minSegmentLength(double voxel_mm) const { return min_segment_length_mm ? *min_segment_length_mm : voxel_mm / 20; }
  void useVascuSynthRules() {
    rules = "vascusynth";
    min_length_ratio = 0;
    relax_sweeps = 0;
    avoid_intersections = false;
  }
};

// Grows the tree; throws GrowthError when the domain cannot take N terminals.
VascularTree growVascuSynth(const DemandMap& map, const GrowthOptions& options, GrowthReport& report, const ProgressFn& progress = {});

}  // namespace angiosynth
