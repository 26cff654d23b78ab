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
#include "settings/schema.hpp"
#include "settings/settings_json.hpp"
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
double declaredQuantity(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table, const std::string& key,
                        Dimension dim, double voxel_mm = 0);
// table.key as a plain number, or the declared default.
double declaredNumber(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table, const std::string& key);

// table.key as a whole number in [lo, hi] (checked before it is narrowed), or the declared default.
int declaredCount(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table, const std::string& key, std::int64_t lo,
                  std::int64_t hi);

// The reference rows of declared settings, for key checks and `angiosynth methods`.
template <class Options>
std::vector<MethodParam> settingRows(const std::vector<Setting<Options>>& settings) {
  std::vector<MethodParam> rows;
  for (const auto& s : settings) rows.push_back({s.table, s.key, s.unit, s.fallback, s.meaning});
  return rows;
}

// Rows of several lists, in order.
std::vector<MethodParam> joinRows(std::initializer_list<std::vector<MethodParam>> lists);

// One [physics] setting of the flow-driven methods as they share it (murray_exponent,
// murray_band_edges, murray_band_exponents (default "none"), cost_radius_exponent, cost_length_exponent, viscosity, perfusion_pressure, terminal_pressure,
// perfusion_flow), with the method's default (nullptr: required), which is its value.
Setting<PhysicsParameters> physicsSetting(const char* key, const char* fallback);
// perfusion_pressure above terminal_pressure by at least 0.001 Pa.
const std::vector<SettingRule<PhysicsParameters>>& physicsRules();
// Murray bands: one exponent more than edges, edges rising by 1.25 times at least.
const std::vector<SettingRule<PhysicsParameters>>& murrayBandRules();

// [physics] of a file read through the method's declarations; the rules checked when both
// pressures are declared.
PhysicsParameters readPhysics(const TomlReader& r, const std::vector<Setting<PhysicsParameters>>& settings, const toml::table& ph);

// Where each key of `t` stands in the file, for checkRules.
inline auto keysIn(const TomlReader& r, const toml::table& t) {
  return [&r, &t](const char* key) -> std::optional<Where> {
    if (t.get(key)) return r.at(t, key);
    return std::nullopt;
  };
}

// The root from [tree] (or the named table): root_voxel (in `voxels`) is stored in root_voxel; root (mm) is returned.
// Exactly one of them is required.
std::optional<Vec3> readRoot(const TomlReader& r, const toml::table& tree, Vec3& root_voxel, int& root_line, const std::string& voxels,
                             const std::string& why_required, const std::string& table = "tree");
// The declared [physics] settings with units, and the flow of each terminal, as sample.json records them.
void describePhysics(const std::vector<Setting<PhysicsParameters>>& settings, const PhysicsParameters& p, std::int64_t terminals,
                     nlohmann::ordered_json& j);

}  // namespace angiosynth
