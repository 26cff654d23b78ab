#pragma once
// Curved vessels for every method: after growth, each vessel (a chain of segments
// between the root, bifurcations and terminals) becomes a smooth curve through its end points,
// drawn as a chain of short straight pieces that every later stage already treats exactly.
// The curve is the vessel's own path plus a lateral Catmull-Rom displacement that vanishes at
// both ends, scaled so that the vessel's distance metric (arc length over chord, Bullitt 2003)
// reaches the requested tortuosity (or its sum of angles per mm, Bullitt 2003, the requested
// value). Curves that would leave the domain, enter zero demand or
// overlap another vessel are flattened (amplitude halved) until they fit, down to the straight
// vessel growth made. Radii and flows stay; pressures follow the longer paths (Poiseuille).
#include <cstdint>
#include <optional>

#include "core/vascular_tree.hpp"
#include "domain/demand_map.hpp"

namespace angiosynth {

class GrowthDomain;

struct CurveOptions {
  bool enabled = false;
  double tortuosity = 1.2;   // the target distance metric of each vessel (≥ 1)
  double tortuosity_sd = 0;  // normal spread of the target between vessels (relative for sum_of_angles)
  // The target as the sum of angles per mm instead (rad/mm, as `stats` measures it).
  std::optional<double> sum_of_angles;
  std::optional<double> wavelength_mm;     // the curve's wavelength; unset: wavelength_radii × the vessel's radius
  std::optional<double> wavelength_radii;  // unset: 40
  std::optional<double> piece_mm;          // longest piece; unset: one voxel of the frame
  double wavelength(double radius_mm) const { return wavelength_mm ? *wavelength_mm : wavelength_radii.value_or(40) * radius_mm; }
  double wall_clearance_mm = 0;  // beyond the radius, from the domain's wall
  bool avoid_overlaps = true;
};

struct CurveReport {
  std::int64_t vessels = 0;           // chains between root, bifurcations and terminals
  std::int64_t curved = 0;            // vessels that moved
  std::int64_t already_tortuous = 0;  // their own path already meets the target
  std::int64_t flattened_by_domain = 0;
  std::int64_t flattened_by_overlap = 0;
  std::int64_t straightened = 0;  // flattened all the way back to growth's shape
  std::int64_t overlap_rounds = 0;
  std::int64_t overlapping_vessel_pairs = 0;  // left at the end, beyond those growth made
  std::int64_t nodes_before = 0, nodes_after = 0;
  double tortuosity_mean = 1, tortuosity_min = 1, tortuosity_max = 1;  // measured, over all vessels
  double target_error_max = 0;                                         // |measured − target| over vessels curved at full amplitude
  bool target_sum_of_angles = false;                                   // the target was the sum of angles per mm
};

// The curved tree (roots, bifurcations and terminals where they were; a forest's tree ids kept).
// Random draws come from (seed, sample, Stage::Curves, the vessel's first segment id), so the
// result does not depend on thread count. `domain` may be null (the frame's box then bounds it).
// Throws InputError, before drawing, when the pieces would need more than `memory_limit` bytes.
VascularTree curveVessels(const VascularTree& t, const CurveOptions& o, const GrowthDomain* domain, const DemandMap& frame, std::uint64_t seed,
                          std::uint64_t sample, CurveReport& report, std::uint64_t memory_limit = 0);

// Arc length over chord of every vessel of a tree (chains of continuation nodes joined).
struct VesselPath {
  std::int32_t start = -1;             // root or bifurcation node
  std::vector<std::int32_t> segments;  // in order from start
};
std::vector<VesselPath> vesselPaths(const VascularTree& t);
double distanceMetric(const VascularTree& t, const VesselPath& v);

}  // namespace angiosynth
