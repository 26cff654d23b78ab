#pragma once
// Published vascular morphometry as data, and how far a tree's statistics lie from it. A
// reference is a TOML file (the shipped ones live in data/morphometry/ and are compiled in by
// name) or another tree's `stats` directory (its vessels.csv and bifurcations.csv as samples).
// One front door: `readMorphometryReference`, `compareMorphometry`, `MorphometryComparison`.
//
// Each statistic is compared by what the reference gives: samples by the two-sample
// Kolmogorov–Smirnov statistic D; a mean with a spread by the standardised difference
// d = (tree − reference) / spread (Horton's ratios in log space), turned into the KS distance
// between two normal laws d spreads apart, 2Φ(|d|/2) − 1. Both lie in [0, 1]; the overall
// figure is their mean.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "morphometry/morphometry.hpp"

namespace angiosynth {

struct ReferenceStatistic {
  std::string name;                          // as `stats` names it: area_ratio, murray_exponent, radius_mm, …
  double lower_mm = 0, upper_mm = INFINITY;  // band of parent radius (bifurcations) or radius (vessels)
  bool median = false;                       // compare the tree's median (else its mean) with `mean`
  double mean = NAN;                         // a summary: its location
  double spread = NAN;                       // its standard deviation, or the scale the file declares
  std::string spread_note;                   // "sd", or why the scale (no spread published)
  std::int64_t count = 0;                    // measurements behind it (0: not given)
  std::vector<double> samples;               // instead of a summary
  std::string source;                        // the table or figure
};

// One row of a table by Strahler order: element diameter and length with their SDs, and the
// number of elements of the order in the whole tree (NaN: not given).
struct StrahlerReferenceRow {
  int order = 0;
  double diameter_mm = NAN, diameter_sd_mm = NAN, length_mm = NAN, length_sd_mm = NAN, elements = NAN;
};

struct MorphometryReference {
  std::string name, title, citation, source, species, organ, vessels, method, file;
  std::string group = "all";  // the tree's group it describes: "all", "kind artery", …
  std::vector<StrahlerReferenceRow> strahler;
  int ratio_from = 0, ratio_to = 0;  // orders Horton's ratios are fitted over
  bool diameter_defined = true;      // its orders are diameter-defined (else topological Strahler orders)
  std::string strahler_definition, strahler_source;
  std::vector<ReferenceStatistic> statistics;
};

// A reference TOML file, a `stats` output directory, or the name of a shipped reference.
MorphometryReference readMorphometryReference(const std::string& file_dir_or_name);
// The shipped references' names (data/morphometry/*.toml, compiled in).
std::vector<std::string> shippedMorphometryReferences();

struct ComparisonRow {
  std::string statistic;
  double lower_mm = 0, upper_mm = INFINITY;
  std::string test;                    // "ks" (samples), "standardised", "standardised (log)" (Horton's ratios)
  double tree = NAN, reference = NAN;  // locations (ks: medians)
  double reference_spread = NAN;       // sd or scale (log space for Horton's ratios)
  std::int64_t tree_count = 0, reference_count = 0;
  double statistic_value = NAN;  // d, or KS D
  double p_value = NAN;          // KS: asymptotic two-sided p
  double distance = NAN;         // in [0, 1]; NaN: the tree has none to compare
  std::string source;
};

struct MorphometryComparison {
  std::string reference, title, citation, group;
  std::vector<ComparisonRow> rows;
  double overall = NAN;  // mean distance over the rows the tree could answer
  std::int64_t compared = 0;
  nlohmann::ordered_json toJson() const;
  std::string table() const;  // for the terminal
};

MorphometryComparison compareMorphometry(const Morphometry& m, const MorphometryReference& reference);

// Two-sample Kolmogorov–Smirnov: D and its asymptotic two-sided p (Stephens 1970's correction).
struct KsResult {
  double d = NAN, p = NAN;
};
KsResult kolmogorovSmirnov(std::vector<double> a, std::vector<double> b);

}  // namespace angiosynth
