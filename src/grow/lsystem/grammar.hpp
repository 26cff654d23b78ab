#pragma once
// The stochastic vessel grammar of Galarreta-Valverde et al. (2013), as V-System uses it:
//   F(d) → {S(d)} [+(θ1) /(β) F(d1)] [−(θ2) /(β) F(d2)]
// a stem S of `stem_segments` pieces with alternating turns of ±`stem_angle` (one of its two
// mirror forms at random), length ε·d·U(1 − m, 1 + m); daughters d1 ~ N(d/2^(1/k), sd·d/2^(1/k))
// and d2 by Murray's law (or both d·ratio), turned by Zamir's optimal angles (or a fixed angle)
// and rolled by β. Expanded breadth first, generation by generation, in physical units inside a
// domain: a stem that would leave the domain (or come closer to its wall than `wall_clearance`
// plus its radius) or overlap a vessel is drawn again, up to `tries` times, then dropped with its
// subtree. The run fails when fewer tips than `min_tip_fraction`·2^n remain.
#include <optional>
#include <cstdint>
#include <string>

#include "core/vascular_tree.hpp"
#include "domain/growth_domain.hpp"
#include "grow/common/growth_report.hpp"

namespace angiosynth {

struct GrammarOptions {
  int iterations = 6;                   // n: generations of bifurcations
  std::optional<double> root_diameter;  // d0, mm (unset: a share of the domain's diameter, set when prepared)
  double length_ratio = 10;             // ε: a stem is ε·d long
  double length_margin = 0.2;           // m: relative half-width of the stem length
  double diameter_sd = 0.2;             // d1's standard deviation relative to d/2^(1/k) (0: exact)
  double murray_exponent = 3;           // k
  // k by band of the parent's radius instead (as [physics] murray_band_edges, mm, and _exponents).
  std::vector<double> murray_band_edges, murray_band_exponents;
  bool murray = true;  // false: both daughters d·radius_ratio
  double radius_ratio = 0.7937;
  bool zamir_angles = true;  // false: ±branch_angle
  double branch_angle = 35;  // deg
  double angle_sd = 0;       // deg, added to each daughter's angle
  double roll_angle = 70;    // deg
  double roll_sd = 0;        // deg
  int stem_segments = 5;
  double stem_angle = 25;  // deg
  bool avoid_collisions = true;
  double wall_clearance = 0;  // mm beyond the vessel's radius
  int tries = 8;
  double min_tip_fraction = 0.9;
  Vec3 root, direction;  // mm in the frame; unit heading of the first stem
  const GrowthDomain* domain = nullptr;
  std::uint64_t seed = 1, sample = 0;
};

struct GrammarReport {
  std::int64_t asked_tips = 0, tips = 0;
  std::int64_t redrawn = 0;            // stems drawn again
  std::int64_t dropped_outside = 0;    // branches dropped: no draw stayed in the domain
  std::int64_t dropped_collision = 0;  // branches dropped: every draw overlapped a vessel
};

// Zamir's optimal angles of daughters with diameters d1, d2 to the parent (radians), as V-System
// computes them (Liu et al. 2010, Zamir et al. 1988), α = d2/d1.
void zamirAngles(double d1, double d2, double& theta1, double& theta2);

// The tree (node 0 the root; radii set, flows not); throws GrowthError when too few tips remain.
VascularTree growGrammar(const GrammarOptions& o, GrammarReport& report, const ProgressFn& progress);

}  // namespace angiosynth
