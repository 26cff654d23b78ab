#pragma once
// Reading a method's tables through its declarations: the keys a table may hold and the
// defaults come from GrowthMethod::params, the same list `angiosynth methods` prints.
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/units.hpp"
#include "grow/method.hpp"
#include "settings/toml_reader.hpp"

namespace angiosynth {

std::set<std::string> declaredKeys(const GrowthMethod& m, const std::string& table);
const MethodParam* findParam(const GrowthMethod& m, const std::string& table, const std::string& key);

// [name] of the file (an empty table when absent) with its keys checked: a key that another
// method declares gets "is for method X", any other undeclared key the list of m's keys.
const toml::table& methodTable(const TomlReader& r, const GrowthMethod& m, const std::string& name);
// Checks the keys of a table already in hand (sub-tables such as [[tree.inlet]]).
void checkMethodKeys(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& name);

// table.key as one of `values` (by name), or `fallback` when absent; an unknown word is an
// error listing the allowed ones.
template <class E>
E choice(const TomlReader& r, const toml::table& t, const std::string& table, const std::string& key, E fallback,
         const std::vector<std::pair<const char*, E>>& values) {
  if (!t.get(key)) return fallback;
  const auto v = r.string(t, table, key);
  std::string allowed;
  for (const auto& [name, value] : values) {
    if (v == name) return value;
    allowed += (allowed.empty() ? "" : ", ") + std::string(name);
  }
  throw InputError(r.file(), r.lineOf(t.get(key)), key + " '" + v + "'; allowed: " + allowed);
}

// table.key as a quantity, or the declared default (an error naming the key when it has none).
double declaredQuantity(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table,
                        const std::string& key, Dimension dim, double voxel_mm = 0);
// table.key as a plain number, or the declared default.
double declaredNumber(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table,
                      const std::string& key);

// table.key as a whole number in [lo, hi] (checked before it is narrowed), or the declared default.
int declaredCount(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table,
                  const std::string& key, std::int64_t lo, std::int64_t hi);

// The [physics] declarations of a flow-driven method, appended to `rows`: murray_exponent, the
// cost exponents when `cost_exponents`, viscosity, pressures and flow with the given defaults
// (nullptr: required).
std::vector<MethodParam> withPhysicsParams(std::vector<MethodParam> rows, bool cost_exponents, const char* viscosity,
                                           const char* perfusion_pressure, const char* terminal_pressure,
                                           const char* perfusion_flow);

// [physics] with m's defaults and the shared range checks; cost exponents only when m declares them.
PhysicsParameters readPhysics(const TomlReader& r, const GrowthMethod& m, const toml::table& ph);

// The root from [tree] (or the named table): root_voxel (in `voxels`) is stored in root_voxel; root (mm) is returned.
// Exactly one of them is required.
std::optional<Vec3> readRoot(const TomlReader& r, const toml::table& tree, Vec3& root_voxel, int& root_line,
                             const std::string& voxels, const std::string& why_required, const std::string& table = "tree");
// [tree] terminals, checked; its line is stored for feasibility errors.
std::int64_t readTerminals(const TomlReader& r, const toml::table& tree, int& line);
// viscosity, pressures and flows with units, as sample.json records them.
void describePhysics(const PhysicsParameters& p, std::int64_t terminals, nlohmann::ordered_json& j);

}  // namespace angiosynth
