#pragma once
// Constrained constructive optimisation as Schreiner & Buxbaum 1993 and Karch et al. 1999 define
// it, following OpenCCO's reading (Kerautret et al. (OpenCCO) §2–6), without its quadratic costs:
// - the domain grows with the tree (§3.3.1): positions live in the final domain and lengths are
//   scaled by s = (n/N)^(1/d), so radii in final-domain units are r·s^(-3/4);
// - a terminal is drawn uniformly (or ∝ a demand map) and kept when it lies farther than
//   δ = (|Ω|/n)^(1/d) from every segment, δ × 0.9 after every 100 failed draws (§3.3.2); with a
//   demand map, δ shrinks where demand is above average, by (mean / local)^(1/d);
// - its ν nearest segments (uniform grid, O(1)) each get Kamiya's bifurcation (§3.2), kept when
//   all three new segments lie in the domain, are longer than 2r and, with the path to the root
//   that thickens, overlap no vessel more than one segment away (§3.3.3, §4.4); the connection
//   of least total volume wins (§4.5), and a point none can take is dropped;
// - R̃, β, ρ and terminal counts are updated along the path to the root only (§3.1.3).
// The exact final tree is checked again for intersections, short and outside segments; the few
// offending branches are removed and regrown until none is left.
//
// Forests: several inlets grow together in one domain. Inlets of one system (one kind, e.g. two
// arteries) compete for that system's N terminals: each terminal joins the tree whose cheapest
// connection adds the least volume, and a tree's share of the flow is either fixed (its quota of
// terminals) or the territory it wins. Systems (arteries and veins) each perfuse, or drain, the
// whole domain with their own N terminals, drawn in turn. No vessel of one tree overlaps a vessel
// of another, checked as within a tree (during growth and on the exact final forest).
#include <cstdint>
#include <vector>

#include "core/vascular_tree.hpp"
#include "domain/growth_domain.hpp"
#include "grow/common/growth_report.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

// What a drawn terminal keeps δ from: the terminal points (Kerautret et al.'s Algorithm 2 and
// OpenCCO's code), or every segment (the wording of its §3.3.2), which spreads terminals evenly
// but forces long connections. Either way it lies outside every vessel.
enum class TerminalSpacing { Terminals, Segments };
// Each connection's bifurcation: also from the optimiser of the exact tree volume, started at
// Kamiya's fixed point (Exact), or Kamiya's point alone, as in OpenCCO (Kerautret et al.).
enum class BifurcationPoint { Exact, Kamiya };

struct CcoOptions {
  std::int64_t terminals = 4000;  // N
  Vec3 root_mm;                   // in the domain's frame
  int closest_neighbours = 20;    // ν
  int max_neighbours = 20;        // in 3D ν doubles up to this, then the point is dropped (at
                                  // most ν: it does not double; see connect)
  int kamiya_iterations = 100;
  double kamiya_tolerance = 1e-6;  // of the bifurcation's step, relative to its three lengths
  int draws_before_relaxing = 100;
  double relaxation = 0.9;
  TerminalSpacing spacing_from = TerminalSpacing::Terminals;
  BifurcationPoint bifurcation = BifurcationPoint::Exact;
  PhysicsParameters physics;  // λ = 2 and μ = 1 (volume) are imposed
  std::uint64_t seed = 1;
  std::uint64_t sample = 0;
  int max_repair_rounds = 30;
  std::int64_t max_draws = 2000000;  // consecutive failed draws before giving up
  // Of those, the draws far enough from every vessel that no vessel could connect to: each costs
  // a bifurcation optimisation per neighbour, where a draw too close costs a lookup. Trees that
  // fit showed at most a few hundred in a row (a part's first vessels, beside the trunk), vessels
  // too thick for their domain nothing else (docs/benchmarks.md).
  std::int64_t max_unconnectable = 5000;
  // Organ scale: each terminal's distance threshold starts where the last connection's stood
  // rather than at δ_max, the relative radii of the whole tree are refreshed once it has grown by
  // 1/256 of itself rather than every 64 terminals, and only the lightest of Kamiya's points are
  // refined; each keeps the cost per terminal from growing with the tree (docs/benchmarks.md).
  bool organ_scale = false;
  // Terminals are drawn at least this deep in the domain (mm): a decomposition's trunk, whose
  // terminals continue into the parts.
  double terminal_depth = 0;
};

// One tree of a forest.
struct CcoInlet {
  Vec3 root_mm;                  // in the domain's frame
  int system = 0;                // inlets of one system share its N terminals
  double share = 0;              // fixed share of its system's terminals (and flow); 0: the territory it wins
  double root_pressure = 0;      // Pa; below terminal_pressure the tree drains (a vein)
  double terminal_pressure = 0;  // Pa
};

// Grows one tree per inlet (each system with options.terminals terminals; the inlet's pressures
// replace those of options.physics); the trees in inlet order.
std::vector<VascularTree> growCcoForest(const GrowthDomain& domain, const CcoOptions& options, const std::vector<CcoInlet>& inlets,
                                        GrowthReport& report, const ProgressFn& progress = {});
// The physics of one tree: `p` with the inlet's root and terminal pressures.
PhysicsParameters inletPhysics(PhysicsParameters p, double root_pressure, double terminal_pressure);
// Terminal quotas of a system's inlets from their fixed shares (largest remainder; shares that sum
// to 1 give quotas that sum to n); 0 for inlets that win their territory.
std::vector<std::int64_t> terminalQuotas(const std::vector<double>& shares, std::int64_t n);

// Grows one tree from options.root_mm; throws GrowthError when the domain cannot take N terminals.
VascularTree growCco(const GrowthDomain& domain, const CcoOptions& options, GrowthReport& report, const ProgressFn& progress = {});

}  // namespace angiosynth
