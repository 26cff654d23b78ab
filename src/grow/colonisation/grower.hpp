#pragma once
// Space colonisation with physiological constraints (Rauch & Harders 2021): arterial
// and venous trees grow together towards oxygen drains sampled in the tissue, leaves inside a
// perception cone (eq. 2), inter-nodes inside the Murray-angle shell of a lateral branch
// (eq. 3), with inertia ω (eq. 4); a leaf whose drains spread wider than φ splits into two
// daughters at Murray's minimum-volume angles (eq. 1) in the plane the drains define; radii by
// the generalised Murray law with exponent κ from the leaves up. Drains an artery satisfies
// become CO₂ sources the veins grow to. The tissue grows by Δσ per step; every node and every
// point of every vessel's centreline stays inside the domain.
//
// Frame: positions are in the output (final) frame, mm. A length parameter is its value at the
// last step; at step t it is that times σ_T/σ_t (the tissue has grown by that factor since), so
// an edge made at step t has length step·σ_T/σ_t, and growth turns finer as the tissue grows.
#include <cstdint>
#include <string>
#include <vector>

#include "core/vascular_tree.hpp"
#include "domain/growth_domain.hpp"
#include "grow/common/growth_report.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

// How the angular spread of a leaf's drains is measured (the trigger of a symmetric bifurcation).
enum class SpreadStatistic {
  StandardDeviation,  // the paper: the standard deviation of the angles to the mean direction
  RootMeanSquare,     // the mean squared angle to the mean direction, rooted (a ring of drains spreads)
};
enum class DrainSource { Volume, Surface };

// One parameter set (a [[stage]]: e.g. a superficial, then a deep plexus).
struct ColonisationStage {
  std::string name = "stage_1";
  int steps = 100;
  int drains_per_step = 1000;
  int drain_lifetime = 1;            // steps an unsatisfied drain lives (0: until satisfied)
  double delta_sigma = 0.02;         // Δσ, tissue growth per step
  double step = 0;                   // d, mm (last step's value)
  double perception_distance = 0;    // δ, mm
  double perception_angle = 90;      // γ, degrees: full cone angle
  double satisfaction_distance = 0;  // mm: a drain this close to a node of its system is supplied
  double co2_distance = 0;           // mm: tissue this close to an artery makes CO₂ (a vein drain)
  double drain_spacing = 0;          // mm: minimum distance between drains
  double terminal_radius = 0;        // r of leaves, mm
  double bias = 0.5;                 // ω in [0, 1]
  double bifurcation_spread = 10;    // φ, degrees
  SpreadStatistic spread = SpreadStatistic::StandardDeviation;
  bool lateral = true;  // inter-nodes may take lateral branches
  DrainSource source = DrainSource::Volume;
  double surface_depth = 0;              // surface drains: within this depth of the border, mm
  const GrowthDomain* drains = nullptr;  // where its drains are sampled (a region of the world, or the world)
};

struct ColonisationRoot {
  Vec3 position;   // mm in the frame
  Vec3 direction;  // unit: where the root vessel heads
  bool vein = false;
  // A stump of an existing tree (in the frame, node 0 its root at `position`): its vessels keep
  // their geometry and grow on; leaves keep their radius.
  const VascularTree* stump = nullptr;
};

struct ColonisationOptions {
  const GrowthDomain* world = nullptr;  // every node and centreline stays inside
  std::vector<ColonisationStage> stages;
  std::vector<ColonisationRoot> roots;
  double murray_exponent = 2.55;  // κ in (2, 4)
  // κ by parent-radius band instead (as [physics] murray_band_edges, mm, and _exponents): the
  // final radii exactly, the angles and growing radii from the radii as they stand.
  std::vector<double> murray_band_edges, murray_band_exponents;
  double sigma0 = 1;            // σ_0, the tissue's initial size
  bool veins = true;            // grow the venous system (needs a vein root)
  bool avoid_crossing = false;  // no new vessel closer to another than their radii
  std::uint64_t seed = 1, sample = 0;
};

struct ColonisationReport {
  std::int64_t arterial_drains = 0, venous_drains = 0;  // sampled / converted over the run
  std::int64_t satisfied = 0;                           // arterial drains satisfied
  std::int64_t bifurcations = 0, lateral_branches = 0, elongations = 0;
  std::int64_t outside_rejected = 0, crossing_rejected = 0;
  std::int64_t pruned = 0;                   // avoid_crossing: branches removed after growth
  std::vector<std::int64_t> nodes_per_step;  // nodes of both systems after each step
  double check_seconds = 0;                  // the final crossing count (not growth)
};

// The trees, one per root in `roots` order (each a single tree with node 0 its root), with
// positions, Murray radii (κ), depth and lengths set; flows and pressures are the caller's.
std::vector<VascularTree> growColonisation(const ColonisationOptions& o, GrowthReport& report, ColonisationReport& cr, const ProgressFn& progress);

// The scale factor σ_T/σ_t of every step of the run (all stages), in order.
std::vector<double> colonisationScales(const ColonisationOptions& o);

// Symmetric daughters' angle to the parent direction, radians: arccos(2^(2/κ−1)).
double symmetricMurrayAngle(double kappa);
// κ, or κ by band of parent radius, of the options.
MurrayLaw colonisationLaw(const ColonisationOptions& o);
// Angle of a lateral branch of radius rb off a parent of radius rp (continuation by Murray's law
// with κ), radians, eq. (1).
double lateralMurrayAngle(double rp, double rb, double kappa);

}  // namespace angiosynth
