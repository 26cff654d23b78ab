#pragma once
// CCO by domain decomposition, so that one tree can be grown by many processes (the idea of
// Cury et al. 2021, on this program's CCO grower):
// 1. the trunk: a CCO tree of K terminals over the whole domain (cheap; every task grows the
//    same one from the seed);
// 2. K parts: trunk terminal i's cell (the voxels nearer to it than to any other terminal along
//    paths in the domain that keep a clearance from the trunk's vessels) grows its share of the N terminals (∝ the cell's demand) as an ordinary CCO
//    tree rooted at that terminal. Parts are independent: threads, array tasks or machines;
// 3. the join: each part hangs from its trunk terminal (its vessel continued by a short stretch
//    out of the trunk's clearance, whose end is the part's root),
//    the whole tree's physics is solved once, and every vessel is checked against every other.
// The cells are disjoint and every part vessel lies inside its cell, so vessels of different
// parts cannot meet; the clearance keeps them off the trunk. A part is grown with a lower
// pressure at its root than it will have in the whole tree (part_pressure_share), so the
// solve can only make its vessels thinner, uniformly: what the part's growth checked still holds.
#include <cstdint>
#include <vector>

#include "core/vascular_tree.hpp"
#include "domain/growth_domain.hpp"
#include "grow/cco/grower.hpp"

namespace angiosynth {

struct CcoDecompositionOptions {
  CcoOptions cco;  // the whole tree: N terminals, its root, physics and seed
  int parts = 0;   // K, the trunk's terminals (at least 2)
  // The trunk is grown with radii this many times those it would have alone (a pressure drop
  // factor⁴ times smaller): a bound on its radii in the whole tree, larger as the whole tree's
  // resistance is (checked by the join: largest_trunk_radius_share). Parts keep out of those
  // radii and a voxel of the domain more.
  double trunk_radius_factor = 2;
  // A part is grown with this share of the root-to-terminal pressure drop across it; the whole
  // tree leaves it more (measured: docs/benchmarks.md), so the join only shrinks its radii.
  double part_pressure_share = 0.4;
  // Voxel of the parts' grids (mm); 0: half the domain's, or the domain's own where it is a
  // quarter of the terminals' spacing or less. Parts lose a voxel at the domain's border and on
  // each side of a border between two parts.
  double part_voxel_mm = 0;
};

// What every task computes first, identically: the trunk and the parts' shares.
struct CcoTrunk {
  VascularTree tree;                         // grown alone, with equal flows to its terminals
  std::vector<std::int32_t> terminal_node;   // node of part i's root, part order
  std::vector<std::int64_t> part_terminals;  // N_i, summing to N
  std::vector<double> clearance_mm;          // per trunk segment (index = node): parts keep out of
  std::vector<Vec3> clearance_end;           // the capsule from its proximal node to here, this wide
  double domain_voxel_mm = 0;
  double part_voxel_mm = 0;        // of the parts' grids
  std::vector<std::int16_t> cell;  // per voxel of the domain's grid: its part, or -1
  double unreached_share = 0;      // of the domain's demand, in no cell (enclosed by the trunk's clearance)
};

struct CcoPart {
  VascularTree tree;  // in the domain's frame; node 0 is the trunk terminal
  GrowthReport report;
  double seconds = 0;
  int attempt = 0;  // of its seed
};

using CcoDecompositionSummary = DecompositionReport;

// Stage 1: grows the trunk and splits the N terminals among the parts; throws GrowthError.
CcoTrunk planCcoTrunk(const GrowthDomain& domain, const CcoDecompositionOptions& opt);
// Part i's growth domain: its cell less the trunk's clearance, on a grid cropped to the cell;
// `offset_mm` is where that grid's origin lies in the domain's frame.
GrowthDomain ccoPartDomain(const GrowthDomain& domain, const CcoTrunk& trunk, int part, Vec3& offset_mm);
// Stage 2: grows part i from its own seed (attempt k: its k-th next), the same tree whatever the threads.
CcoPart growCcoPart(const GrowthDomain& domain, const CcoTrunk& trunk, int part, const CcoDecompositionOptions& opt, int attempt = 0);
// Stage 3: the whole tree from the trunk and every part, solved and checked; the parts whose
// vessels meet others' are listed (summary.offending_parts), to be grown again.
VascularTree joinCcoParts(const GrowthDomain& domain, const CcoTrunk& trunk, const std::vector<CcoPart>& parts, const CcoDecompositionOptions& opt,
                          CcoDecompositionSummary& summary);
// Stage 3 with the repair: the parts whose vessels meet others' are grown again from their next
// seeds (in `parts`), for up to 4 rounds (what is left then stays in the summary's counts).
VascularTree joinCcoPartsRegrowing(const GrowthDomain& domain, const CcoTrunk& trunk, std::vector<CcoPart>& parts, const CcoDecompositionOptions& opt,
                                   CcoDecompositionSummary& summary);
// The growth report of the joined tree: the parts' counts summed, the whole tree's checks and the summary.
GrowthReport decomposedReport(const std::vector<CcoPart>& parts, const CcoDecompositionSummary& summary, const VascularTree& joined);
// All three in one process, the parts in parallel; offending parts are grown again, for up to
// 4 rounds (what is left then stays in the summary's counts).
// The report is decomposedReport's.
VascularTree growCcoDecomposed(const GrowthDomain& domain, const CcoDecompositionOptions& opt, GrowthReport& report, const ProgressFn& progress = {});

}  // namespace angiosynth
