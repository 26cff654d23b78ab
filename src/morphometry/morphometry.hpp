#pragma once
// Morphometry of vascular trees: what a physiologist measures on a cast or a reconstruction,
// measured on any tree the program grows or reads. One front door: `MorphometryOptions`,
// `measureTrees`, `Morphometry` (per vessel, per bifurcation, and their summaries).
//
// A vessel runs from a root or a branching node to the next branching node or terminal,
// through the pieces of a curved vessel (continuation nodes); a junction's links (zero-length
// segments of an N-ary node) are one branching point.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/vascular_tree.hpp"
#include "io/volume_writers.hpp"

namespace angiosynth {

struct MorphometryOptions {
  // Lower edges of the parent-radius bands (mm) in which Murray's exponent is fitted: the default
  // bands split at 0.1 and 1 mm, where published exponents move from near 3 to near 2.3.
  std::vector<double> murray_band_edges_mm{0.1, 1.0};
};

struct VesselMeasures {
  std::int32_t id = 0;             // its distal segment's id (the node where it ends)
  std::int32_t proximal_node = 0;  // where it starts
  std::int32_t tree = 0;
  std::int32_t parent = -1;  // the vessel it leaves (-1: a root vessel)
  std::int32_t pieces = 0;   // segments it is made of
  double length_mm = 0;      // along its pieces
  double chord_mm = 0;       // between its ends
  double radius_mm = 0;      // length-weighted mean radius of its pieces
  double length_over_radius = 0;
  double distance_metric = 1;         // tortuosity: length / chord (Bullitt et al. 2003)
  std::int32_t inflections = 0;       // changes of turning direction along it (inflection count metric)
  double sum_of_angles_per_mm = 0;    // Σ total curvature angle (in-plane and torsion) / length (rad/mm)
  double path_length_to_root_mm = 0;  // from the root to its proximal node, along the tree
  std::int32_t generation = 0;        // branching points between the root and it (root vessel 0)
  std::int32_t strahler = 1;          // Strahler order: terminal vessels 1
  bool terminal = false;
};

struct BifurcationMeasures {
  std::int32_t node = 0, tree = 0;
  std::int32_t parent = 0, daughter_large = 0, daughter_small = 0;  // vessel ids
  double r_parent_mm = 0, r_large_mm = 0, r_small_mm = 0;           // at the branching point
  double angle_large_deg = 0, angle_small_deg = 0;                  // each daughter against the parent's direction (0: straight on)
  double angle_between_deg = 0;                                     // between the daughters
  double out_of_plane_deg = 0;                                      // the parent's direction against the daughters' plane (0: coplanar)
  double asymmetry = 0;                                             // r_small / r_large
  double area_ratio = 0;                                            // (r_large² + r_small²) / r_parent²
  double daughter_area_ratio = 0;                                   // r_small² / r_large²
  double murray_exponent = 0;  // γ with r_parent^γ = r_large^γ + r_small^γ (NaN: none, a daughter as wide as the parent)
};

struct Summary {
  std::int64_t count = 0;
  double mean = 0, sd = 0, min = 0, p05 = 0, p25 = 0, median = 0, p75 = 0, p95 = 0, max = 0;
};
Summary summarise(std::vector<double> values);  // NaNs left out

struct StrahlerOrder {
  std::int32_t order = 0;
  std::int64_t vessels = 0, elements = 0;  // elements: runs of vessels of this order joined
  double mean_element_length_mm = 0, mean_element_diameter_mm = 0;
};

struct MurrayBand {
  double lower_mm = 0, upper_mm = 0;  // of the parent radius
  std::int64_t bifurcations = 0;
  double median_exponent = 0;  // of the per-bifurcation exponents
  double fitted_exponent = 0;  // minimising Σ (x_large^γ + x_small^γ − 1)², x = r / r_parent (NaN: none)
};

// Horton's ratios: branching N_k/N_{k+1}, length and diameter L_{k+1}/L_k, D_{k+1}/D_k of the
// elements by order (NaN with fewer than two orders).
struct HortonRatios {
  double branching = 0, length = 0, diameter = 0;
};

// The statistics of one group of vessels (a tree, a kind, or all).
struct MorphometryGroup {
  std::string name;
  std::vector<std::int32_t> trees;  // the trees it holds (ids, ascending)
  std::int64_t vessels = 0, bifurcations = 0, junctions = 0, terminals = 0;
  std::map<std::string, Summary> summaries;  // by statistic (radius_mm, length_mm, …)
  std::vector<StrahlerOrder> strahler;
  // Horton's ratios from the elements' regression on order: branching N_k/N_{k+1}, length and
  // diameter L_{k+1}/L_k, D_{k+1}/D_k (NaN with fewer than two orders).
  double horton_branching = 0, horton_length = 0, horton_diameter = 0;
  // The same by diameter-defined Strahler orders (Kassab et al. 1993; Jiang et al. 1994), as
  // published morphometry of casts orders vessels.
  std::vector<StrahlerOrder> diameter_orders;
  HortonRatios horton_by_diameter;
  std::vector<MurrayBand> murray_bands;
  double murray_fitted = 0;                  // over all its bifurcations
  double terminal_nearest_neighbour_mm = 0;  // mean distance from a terminal to the nearest other terminal of the group
};

struct Morphometry {
  std::vector<VesselMeasures> vessels;
  std::vector<BifurcationMeasures> bifurcations;
  std::vector<MorphometryGroup> groups;  // "all", then each kind (two or more), then each tree (two or more)
  // How the CSVs name a vessel: the file's id of its distal segment (node id → name; empty: the
  // node id itself).
  std::vector<std::string> segment_names;
  std::vector<std::string> tree_kinds;  // per tree, as measured ("tree" where none was given)
  nlohmann::ordered_json toJson() const;
  std::string vesselName(std::int32_t vessel) const;
  std::string vesselsCsv() const;
  std::string bifurcationsCsv() const;
};

// `tree_kinds[t]`: the kind of tree t (empty: "tree"); `tree_names[t]` its name.
Morphometry measureTrees(const VascularTree& tree, const std::vector<std::string>& tree_names, const std::vector<std::string>& tree_kinds,
                         const MorphometryOptions& options = {});

// A figure of the distributions: one histogram per statistic (vessel radius, length, length /
// radius, distance metric, generation; the bifurcations' angles, asymmetry and Murray exponent),
// each kind a curve in its colour when there are two or more, and element counts by Strahler
// order on a log scale.
Image8 morphometryFigure(const Morphometry& m);

// Least-squares slope of y on x (NaN with fewer than two points or one x).
double leastSquaresSlope(const std::vector<double>& x, const std::vector<double>& y);

// The statistics per vessel and per bifurcation by the names of vessels.csv and bifurcations.csv
// (radius_mm, length_over_radius, …, asymmetry, murray_exponent): one value each.
const std::vector<std::pair<std::string, double (*)(const VesselMeasures&)>>& vesselStatistics();
const std::vector<std::pair<std::string, double (*)(const BifurcationMeasures&)>>& bifurcationStatistics();

// γ with x1^γ + x2^γ = 1 (0 < x1, x2 < 1), by bisection to 1e-12; NaN when none.
double murrayExponent(double r_parent, double r1, double r2);

}  // namespace angiosynth
