#pragma once
// [[region]] tables (named analytic shapes, relative to the domain's centre) and the helpers
// their readers share: a stage names regions.
#include <set>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "grow/common/method_tables.hpp"
#include "grow/common/regions.hpp"
#include "io/network_files.hpp"

namespace angiosynth {

// The region names of t.key (one name or an array), each defined in `known`.
std::vector<std::string> regionNames(const TomlReader& r, const toml::table& t, const std::string& key, const std::set<std::string>& known);
// Every [[region]] of the file, keys checked against m's declarations.
std::vector<RegionSpec> readRegions(const TomlReader& r, const GrowthMethod& m, bool flat);
// [initial] (checked against m's declarations): the network file (beside the parameter file),
// read in its `unit` (mm, cm, m, um), and whether its positions start at the grid's corner
// (`origin = "corner"`) rather than the domain's centre.
struct InitialNetwork {
  std::filesystem::path file;
  ExistingNetwork network;
  bool from_corner = false;
};
// `flat`: the domain is 2D, so the network must lie in one plane (its common z is dropped).
InitialNetwork readInitialNetwork(const TomlReader& r, const GrowthMethod& m, const toml::node& node, bool flat);

// The [[region]] declarations (`used_by` says which keys name regions), appended to `rows`.
std::vector<MethodParam> withRegionParams(std::vector<MethodParam> rows, const char* used_by);

}  // namespace angiosynth
