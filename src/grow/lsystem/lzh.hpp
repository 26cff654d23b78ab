#pragma once
// Lázaro 2011: a printable closed vessel network from high-level parameters. The
// inverse problem turns the block size, the start and capillary vessels and the capillary
// spacing into the L-system's levels N, angle θ and lengths L_n; a 3D turtle with a 90° roll per
// level draws the "middle tree"; the venous half is its mirror image through the block's
// mid-plane, joined to it by vertical capillaries: inlet → arteries → capillaries → veins → outlet.
// Diameter and wall thickness are linear in the path length from the inlet (tapered vessels).
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/forest.hpp"

namespace angiosynth {

struct LzhParameters {
  int dimension = 3;                // 2: one plane; 3: levels alternate between two planes
  double block_width = 0;           // w_b, mm (the block is w_b × w_b × h; in 2D w_b × h)
  double height = 0;                // h, mm: inlet top to outlet bottom
  double start_length = 0;          // L_s, mm: the vertical inlet (and outlet) vessel
  double capillary_length = 0;      // L_c, mm
  double start_diameter = 0;        // d_s, mm (lumen)
  double capillary_diameter = 0;    // d_c, mm
  double start_wall = 0;            // t_ws, mm
  double capillary_wall = 0;        // t_wc, mm
  double spacing = 0;               // d, mm: the largest distance allowed between capillaries
  bool printed_level_rule = false;  // N = ⌈log2(c/d)⌉ as printed (leaves may lie farther apart than d)
  double perfusion_flow = 0;        // mm³/s into the inlet (0: no flows or pressures)
  double perfusion_pressure = 0;    // Pa at the inlet
  double viscosity = 3.6e-3;        // Pa·s
};

// A parameter that makes the network impossible: the key it names and why.
struct LzhError : std::invalid_argument {
  std::string key;
  LzhError(std::string k, const std::string& what) : std::invalid_argument(what), key(std::move(k)) {}
};

struct LzhPlan {
  int levels_2d = 0;           // N of one plane's tree (leaves 2^N per lateral axis)
  int levels = 0;              // bifurcation levels of the middle tree: N (2D) or 2N (3D)
  double theta = 0;            // rad, every branch's angle to the vertical
  double leaf_span = 0;        // c = w_b − d: the capillaries' extent per lateral axis
  double middle_height = 0;    // h_m = (h − 2 L_s − L_c)/2
  double w = 0;                // c·2^N/(2^N − 1)
  std::vector<double> offset;  // w_n, n < N: lateral offset of a level-n branch
  std::vector<double> length;  // L of each middle-tree level (levels entries)
  double leaf_spacing = 0;     // c/(2^N − 1)
  std::int64_t leaves = 0;     // 2^N (2D) or 4^N (3D)
  std::int64_t nodes = 0;      // of the whole network
};

// The inverse problem (Lázaro 2011 §4, Algorithm 4.1); throws LzhError.
LzhPlan planLzh(const LzhParameters& p);

// The network in a frame whose block corner is at `corner` (mm): tree 0 the inlet's arterial
// tree, then one tree per capillary (its root at an arterial leaf), then the outlet's venous
// tree (its root at the outlet, its leaves at the capillaries' lower ends). Vertical is y in
// 2D (z = `plane_z`), z in 3D. Flows split equally over the capillaries; pressures fall from the
// inlet by Poiseuille's law for truncated cones.
Forest buildLzhNetwork(const LzhParameters& p, const LzhPlan& plan, const Vec3& corner, double plane_z = 0);

// Poiseuille resistance of a vessel whose radius goes linearly from a to b over length l
// (8ηl/(3π)·(a² + ab + b²)/(a³b³); 8ηl/(πr⁴) when a = b), Pa·s/mm³.
double taperedResistance(double viscosity, double l, double a, double b);

}  // namespace angiosynth
