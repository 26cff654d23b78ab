#pragma once
// What every growth method reports: counts of drawn, rejected and repaired candidates, the
// final checks (targets 0), progress callbacks and the error for a domain that cannot be filled.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace angiosynth {

// A tree grown in parts by domain decomposition (grow/cco/decomposition.hpp): how the stages went
// and the margins the construction relies on, as measured on the joined tree.
struct DecompositionReport {
  int parts = 0;
  double trunk_seconds = 0, parts_seconds = 0, join_seconds = 0;
  double slowest_part_seconds = 0;
  std::int64_t terminals = 0;
  std::int64_t intersecting_pairs = 0;  // every vessel against every other, exact (target 0)
  std::int64_t short_segments = 0;      // l <= 2r (target 0)
  std::int64_t outside_segments = 0;    // capsules leaving the domain (target 0)
  // Each part's radii in the whole tree over those it was grown with (<= 1: its checks hold).
  double largest_part_scale = 0, smallest_part_scale = 0;
  // The trunk's final radii over the clearance the parts kept (< 1: the parts kept clear).
  double largest_trunk_radius_share = 0;
  // Pressure drop across each part in the whole tree, as a share of the root-to-terminal drop.
  double smallest_part_pressure_share = 0;
  std::int64_t repaired_terminals = 0;  // summed over the parts' own final checks
  double unreached_share = 0;           // of the demand, in no part (enclosed by the trunk's clearance)
  std::vector<int> offending_parts;     // parts with a vessel in an intersecting pair (to grow again)
  std::int64_t regrown_parts = 0;
};

struct GrowthReport {
  std::int64_t candidates = 0;             // candidate terminals drawn
  std::int64_t rejected_too_close = 0;     // within MIN_DISTANCE of the tree
  std::int64_t rejected_unreachable = 0;   // every trial connection crossed zero demand
  std::int64_t rejected_intersection = 0;  // every admissible connection made vessels intersect
  std::int64_t retracted_terminals = 0;    // terminals pulled back along their segment to clear a vessel
  std::int64_t moved_nodes = 0;            // nodes moved to separate two vessels
  std::int64_t repaired_terminals = 0;     // terminals removed and regrown by the final check
  std::int64_t relaxed_bifurcations = 0;   // vascusynth: bifurcation moves of the final relaxation sweeps
  int repair_rounds = 0;
  std::int64_t intersecting_pairs = 0;  // in the final tree (target 0)
  // CCO only.
  std::int64_t threshold_relaxations = 0;  // δ_max × 0.9 after a run of failed draws
  std::int64_t neighbour_doublings = 0;    // ν doubled because every candidate failed
  std::int64_t kamiya_failures = 0;        // Kamiya's iteration found no bifurcation
  std::int64_t hidden_segments = 0;        // 2D: candidate segments a vessel separates from the point
  std::int64_t crowded_segments = 0;       // candidate segments whose connection a vessel at the point would block
  std::int64_t node_optima = 0;            // candidate segments whose optimum is their proximal node (not refined)
  std::int64_t short_segments = 0;         // final segments with length <= 2 r (target 0)
  // CCO: each segment left shorter than 2r by the final check (one its repair could not fix),
  // by its tree and its ends (mm), so that a user can find it.
  struct ShortSegment {
    int tree;
    double proximal[3], distal[3], length, radius;
  };
  std::vector<ShortSegment> short_list;
  std::int64_t outside_segments = 0;     // final segments leaving the domain (target 0)
  std::int64_t lenient_connections = 0;  // forests: connections whose thickened ancestors were checked only in part
  double root_radius_mm = 0;
  std::optional<DecompositionReport> decomposition;  // CCO grown in parts

  // Every count above, in one fixed order: what a part's file stores and parts add up.
  std::array<std::int64_t*, 18> counts() {
    return {&candidates,         &rejected_too_close,   &rejected_unreachable, &rejected_intersection, &retracted_terminals, &moved_nodes,
            &repaired_terminals, &relaxed_bifurcations, &intersecting_pairs,   &threshold_relaxations, &neighbour_doublings, &kamiya_failures,
            &hidden_segments,    &crowded_segments,     &node_optima,          &short_segments,        &outside_segments,    &lenient_connections};
  }
};

using ProgressFn = std::function<void(std::int64_t done, std::int64_t total)>;

class GrowthError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace angiosynth
