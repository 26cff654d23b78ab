#pragma once
// Domain-constrained CCO (DCCO; Maso Talou et al. 2021 §1.1): the tree grows in stages,
// each with its own domain, terminal count, terminal pdf, geometric and optimisation parameters,
// cost (volume, eq. 10, or sprouting, eq. 15) and the role of the vessels it makes. The root's
// radius and inflow are fixed (not the pressure drop), the domain does not grow with the tree.
//
// Per terminal (Algorithm 2 inside Algorithm 3):
// - x is drawn from the stage's pdf and kept when it lies farther than
//   l_lim = l_c (ν / (N_T + 1))^(1/D) from the tree (eqs. 11–13), l_lim × f_r after every
//   `draws_before_relaxing` rejections in a row (eq. 14);
// - the candidate parents are the vessels within the box of half-side f_n·l_lim around x (VItA's
//   reading of the neighbourhood), nearest first, at most `max_candidates` of them;
// - each candidate is split at the points of its lattice (Δv(Δv+1)/2 − 3 points of the triangle
//   (x, x_p, x_d), fewer for fixed and distal vessels), and every point is costed exactly: the
//   path from the new bifurcation to the root takes its new reduced resistances, radius ratios
//   and subtree volumes (O(depth), viscosities held at their last fixed point);
// - a point is kept when the three new vessels are longer than twice their radii, the new
//   bifurcation is symmetric enough (δ of its level), θ and φ are within their limits, the roles
//   allow where the vessels lie and the split vessel branches, and no vessel overlaps another
//   (radius-aware); the cheapest point wins;
// - radii come from Algorithm 1: Karch's radius update with fixed viscosities, then the
//   viscosities from the radii (constant, or Pries' law), until |Δη/η| < 1e-6 everywhere.
// Every stage ends with the exact fixed point of the whole tree and a check of its constraints;
// the few vessels of the stage that break one are removed and regrown within the stage.
#include <cstdint>
#include <string>
#include <vector>

#include "core/forest.hpp"
#include "core/vessel_roles.hpp"
#include "domain/growth_domain.hpp"
#include "grow/common/growth_report.hpp"
#include "physics/viscosity.hpp"

namespace angiosynth {

enum class StageCost { Volume, Sprout };
enum class TerminalPdf { Uniform, Demand, Gaussian };

// One Gaussian of a terminal pdf: mean relative to the domain's centre, per-axis σ, weight.
struct GaussianComponent {
  Vec3 mean, sigma;
  double weight = 1;
};

struct DccoStage {
  std::string name;
  const GrowthDomain* vessels = nullptr;    // Ω_t without its avascular regions: distribution vessels stay inside
  const GrowthDomain* terminals = nullptr;  // Ω_t without avascular and carriage regions: terminals are drawn here
  std::int64_t terminal_count = 0;          // N^t_T_final, added by this stage
  TerminalPdf pdf = TerminalPdf::Uniform;
  std::vector<GaussianComponent> gaussians;
  double gamma = 3;                // Murray exponent of the bifurcations this stage makes
  std::vector<double> delta{0.0};  // symmetry limit per bifurcation level (the last repeats)
  double nu = 1, f_r = 0.9, f_n = 8;
  int delta_v = 7;
  StageCost cost = StageCost::Volume;
  double c_v = 1, c_p = 0, c_d = 0;       // eq. 15
  double theta_min = 0, theta_max = 180;  // degrees (eq. 17)
  double phi_min = 0, phi_max = 90;       // degrees (eq. 18)
  VesselRole role = VesselRole::Distribution;
  int draws_before_relaxing = 100;  // N_fail
  int max_candidates = 64;          // nearest candidates tried per terminal (VItA: all in the box)
  double deltaAt(int level) const { return delta[std::min<std::size_t>(std::size_t(std::max(level, 0)), delta.size() - 1)]; }
};

struct DccoOptions {
  Vec3 root_mm;                  // in the frame
  double root_radius = 1;        // mm, fixed (r_1)
  double flow = 8330;            // mm^3/s, Q
  double root_pressure = 13300;  // Pa at the root (pressures downstream follow)
  // γ by band of parent radius (mm) for every bifurcation, instead of each stage's γ ([physics]
  // murray_band_edges and _exponents; empty: the stages').
  std::vector<double> murray_band_edges, murray_band_exponents;
  Viscosity viscosity;
  const GrowthDomain* world = nullptr;  // every vessel stays inside (minus the avascular regions of its stage)
  // The network growth continues (Maso Talou et al.'s vascular completion; null: the first stage plants a
  // root vessel at root_mm). Its vessels keep their geometry, role, branching and outflow and
  // take stage -1; each of its roots is an inlet with the fixed radius root_radii[tree] (empty:
  // root_radius), all inlets share Q by the terminals they feed.
  const VascularTree* initial = nullptr;
  std::vector<std::string> initial_names;  // per node of `initial`: how errors name it (its file, line and id)
  std::vector<double> root_radii;
  std::vector<DccoStage> stages;
  std::uint64_t seed = 1, sample = 0;
  int max_repair_rounds = 30;
  std::int64_t max_draws = 1000000;  // draws in a row without a connection before giving up
};

// What DCCO reports beside the common counts.
struct DccoReport {
  std::vector<std::int64_t> stage_terminals;  // terminals each stage added
  std::int64_t threshold_relaxations = 0;
  std::int64_t trial_points = 0;                                                       // lattice points costed
  std::int64_t viscosity_iterations = 0;                                               // of the last fixed point
  std::int64_t short_segments = 0, outside_segments = 0, asymmetric_bifurcations = 0;  // final, target 0
  std::int64_t folded_pairs = 0;  // final: vessels one segment apart whose centrelines cross (target 0)
  double volume_mm3 = 0;
};

// Grows the staged tree; throws GrowthError when a stage cannot place its terminals.
VascularTree growDcco(const DccoOptions& o, GrowthReport& report, DccoReport& dcco, const ProgressFn& progress = {});

// Algorithm 1 on a grown tree: radii from each root's fixed radius (`root_radius` by tree) and
// Karch's update with per-vessel viscosities, viscosities from the radii, until the largest
// relative change is below `tolerance`; fills terminals, β, radii, flows, pressures. Terminals
// with an outflow fraction f_i carry f_i·Q, the others share the rest equally. `gamma_of_stage`
// gives the Murray exponent of the splits each stage made. `load` (if given) receives every
// segment's flow in units of the common terminal flow. Returns the iterations.
int solveDccoTree(VascularTree& t, std::vector<double>& eta, const DccoOptions& o, const std::vector<double>& gamma_of_stage,
                  const std::vector<double>& root_radius, std::vector<double>* load = nullptr, double tolerance = 1e-6);

}  // namespace angiosynth
