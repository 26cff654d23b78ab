#include "grow/common/method_tables.hpp"

#include "core/quantity_json.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {

std::set<std::string> declaredKeys(const GrowthMethod& m, const std::string& table) {
  std::set<std::string> keys;
  for (const auto& p : m.params)
    if (table == p.table) keys.insert(p.key);
  return keys;
}

const MethodParam* findParam(const GrowthMethod& m, const std::string& table, const std::string& key) {
  for (const auto& p : m.params)
    if (table == p.table && key == p.key) return &p;
  return nullptr;
}

void checkMethodKeys(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& name) {
  for (const auto& [k, v] : t) {
    const std::string key(k.str());
    if (findParam(m, name, key) || (name == "tree" && key == "method")) continue;
    if (!declaredKeys(m, name + "." + key).empty()) continue;  // a sub-table the method declares: [[tree.inlet]], [[stage.gaussian]]
    if (const GrowthMethod* other = methodDeclaring(name, key, &m))
      throw InputError(
          r.file(), r.lineOf(&v),
          "'" + key + "' in [" + name + "] is for method " + other->name + "; this file grows with method " + m.name + " ([tree] method)");
    std::string list;
    for (const auto& a : declaredKeys(m, name)) list += (list.empty() ? "" : ", ") + a;
    throw InputError(r.file(), r.lineOf(&v), "unknown key '" + key + "' in [" + name + "] of method " + m.name + "; allowed: " + list);
  }
}

const toml::table& methodTable(const TomlReader& r, const GrowthMethod& m, const std::string& name) {
  const toml::node* n = r.root().get(name);
  if (!n) {
    static const toml::table empty;
    return empty;
  }
  if (!n->is_table()) throw InputError(r.file(), r.lineOf(n), "[" + name + "] must be a table");
  checkMethodKeys(r, m, *n->as_table(), name);
  return *n->as_table();
}

namespace {

const char* fallbackOf(const GrowthMethod& m, const std::string& table, const std::string& key) {
  const MethodParam* p = findParam(m, table, key);
  return p ? p->fallback : nullptr;
}

}  // namespace

double declaredQuantity(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table, const std::string& key,
                        Dimension dim, double voxel_mm) {
  const char* fallback = fallbackOf(m, table, key);
  if (t.get(key) || !fallback) return r.quantity(t, table, key, dim, voxel_mm);
  return parseQuantity(fallback, dim, voxel_mm);
}

double declaredNumber(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table, const std::string& key) {
  const char* fallback = fallbackOf(m, table, key);
  if (t.get(key) || !fallback) return r.number(t, table, key);
  return std::stod(fallback);
}

int declaredCount(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table, const std::string& key, std::int64_t lo,
                  std::int64_t hi) {
  const char* fallback = fallbackOf(m, table, key);
  if (t.get(key) || !fallback) return r.smallInteger(t, table, key, lo, hi);
  return std::stoi(fallback);
}

std::vector<MethodParam> joinRows(std::initializer_list<std::vector<MethodParam>> lists) {
  std::vector<MethodParam> rows;
  for (const auto& l : lists) rows.insert(rows.end(), l.begin(), l.end());
  return rows;
}

// clang-format off
Setting<PhysicsParameters> physicsSetting(const char* key, const char* fallback) {
  using P = PhysicsParameters;
  static const std::vector<Setting<P>> shared{
      {.table = "physics", .key = "murray_exponent", .unit = "", .fallback = nullptr, .meaning = "γ in r_parent^γ = r_a^γ + r_b^γ",
       .field = &P::murray_exponent, .range = {Limits::kMinMurray, Limits::kMaxMurray, true, false}},
      {.table = "physics", .key = "murray_band_edges", .unit = "[\"<length>\" …]", .fallback = nullptr,
       .meaning = "parent radii splitting the bifurcations into bands with a Murray exponent each (murray_band_exponents, which then replace "
                  "murray_exponent): ascending, each at least 1.25 times the one before; γ ramps across an edge over ±5 % of its radius",
       .field = &P::murray_band_edges, .range = {0, 1e6, true, false}, .quantity = Dimension::Length, .range_unit = "mm"},
      {.table = "physics", .key = "murray_band_exponents", .unit = "[γ …]", .fallback = nullptr,
       .meaning = "γ of each band of parent radius, the smallest radii first: one more than murray_band_edges, at most 8",
       .field = &P::murray_band_exponents, .range = {Limits::kMinMurray, Limits::kMaxMurray, true, false}},
      {.table = "physics", .key = "cost_radius_exponent", .unit = "", .fallback = nullptr, .meaning = "λ of the cost Σ l^μ r^λ",
       .field = &P::cost_radius_exponent, .range = {0, Limits::kMaxCostExponent}},
      {.table = "physics", .key = "cost_length_exponent", .unit = "", .fallback = nullptr, .meaning = "μ of the cost Σ l^μ r^λ",
       .field = &P::cost_length_exponent, .range = {0, Limits::kMaxCostExponent}},
      {.table = "physics", .key = "viscosity", .unit = "Pa*s", .fallback = nullptr, .meaning = "blood viscosity η",
       .field = &P::viscosity, .range = {Limits::kMinViscosity, Limits::kMaxViscosity}, .quantity = Dimension::Viscosity},
      {.table = "physics", .key = "perfusion_pressure", .unit = "Pa", .fallback = nullptr, .meaning = "pressure at the root",
       .field = &P::perfusion_pressure, .range = {0, Limits::kMaxPressure}, .quantity = Dimension::Pressure},
      {.table = "physics", .key = "terminal_pressure", .unit = "Pa", .fallback = nullptr, .meaning = "pressure at every terminal",
       .field = &P::terminal_pressure, .range = {0, Limits::kMaxPressure}, .quantity = Dimension::Pressure},
      {.table = "physics", .key = "perfusion_flow", .unit = "mm^3/s", .fallback = nullptr,
       .meaning = "flow into the root, split equally among the terminals",
       .field = &P::perfusion_flow, .range = {Limits::kMinFlow, Limits::kMaxFlow}, .quantity = Dimension::Flow},
  };
  for (auto s : shared)
    if (std::string(s.key) == key) {
      s.fallback = fallback;
      s.fallback_is_value = fallback != nullptr && std::string(fallback) != "none";
      return s;
    }
  throw std::logic_error(std::string("no shared [physics] setting ") + key);
}
// clang-format on

// clang-format off
const std::vector<SettingRule<PhysicsParameters>>& physicsRules() {
  static const std::vector<SettingRule<PhysicsParameters>> rules{
      {{"perfusion_pressure", "terminal_pressure"}, [](const PhysicsParameters& p) {
         return p.perfusion_pressure - p.terminal_pressure >= Limits::kMinPressureDrop
                    ? std::string()
                    : std::string("perfusion_pressure must exceed terminal_pressure by at least 0.001 Pa");
       }}};
  return rules;
}
// clang-format on

// clang-format off
const std::vector<SettingRule<PhysicsParameters>>& murrayBandRules() {
  static const std::vector<SettingRule<PhysicsParameters>> rules{
      {{"murray_band_exponents", "murray_band_edges"}, [](const PhysicsParameters& p) {
         const auto& e = p.murray_band_edges;
         const auto& g = p.murray_band_exponents;
         if (e.empty() && g.empty()) return std::string();
         if (g.size() != e.size() + 1)
           return "murray_band_exponents holds " + std::to_string(g.size()) + " exponents for " + std::to_string(e.size()) +
                  " murray_band_edges; allowed: one exponent more than edges";
         if (g.size() > std::size_t(MurrayLaw::kMaxBands)) return std::string("murray_band_exponents holds more than 8 bands; allowed: 2 … 8");
         return std::string();
       }},
      {{"murray_band_edges"}, [](const PhysicsParameters& p) {
         const auto& e = p.murray_band_edges;
         for (std::size_t k = 1; k < e.size(); ++k)
           if (!(e[k] >= 1.25 * e[k - 1]))
             return "murray_band_edges " + show(e[k - 1]) + " mm and " + show(e[k]) +
                    " mm: allowed: ascending, each edge at least 1.25 times the one before (an edge ramps γ over ±5 % of its radius)";
         return std::string();
       }}};
  return rules;
}
// clang-format on

PhysicsParameters readPhysics(const TomlReader& r, const std::vector<Setting<PhysicsParameters>>& settings, const toml::table& ph) {
  PhysicsParameters p;
  readSettingsFrom(r, ph, "physics", settings, p, 0);
  const auto keys = settingKeys(settings);
  if (keys.count("perfusion_pressure") && keys.count("terminal_pressure"))
    checkRules(physicsRules(), p, keysIn(r, ph), Where{r.file(), r.lineOf(&ph)});
  if (keys.count("murray_band_edges")) checkRules(murrayBandRules(), p, keysIn(r, ph), Where{r.file(), r.lineOf(&ph)});
  return p;
}

std::optional<Vec3> readRoot(const TomlReader& r, const toml::table& tree, Vec3& root_voxel, int& root_line, const std::string& voxels,
                             const std::string& why_required, const std::string& table) {
  if (tree.get("root_voxel") && tree.get("root"))
    throw InputError(r.file(), r.lineOf(tree.get("root")), "give root (mm) or root_voxel (" + voxels + "), not both");
  if (const auto* n = tree.get("root_voxel")) {
    root_voxel = r.point(n, "root_voxel", false);
    root_line = r.lineOf(n);
    return std::nullopt;
  }
  if (const auto* n = tree.get("root")) {
    root_line = r.lineOf(n);
    return r.point(n, "root (mm)", false);
  }
  throw InputError(r.file(), r.lineOf(&tree), "missing key 'root' (mm) or 'root_voxel' (" + voxels + ") in [" + table + "]" + why_required);
}

void describePhysics(const std::vector<Setting<PhysicsParameters>>& settings, const PhysicsParameters& p, std::int64_t terminals,
                     nlohmann::ordered_json& j) {
  j.update(settingsJson(settings, p));
  j["terminal_flow"] = quantityJson(p.perfusion_flow / double(terminals), "mm^3/s");
}

}  // namespace angiosynth
