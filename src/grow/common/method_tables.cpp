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
      throw InputError(r.file(), r.lineOf(&v), "'" + key + "' in [" + name + "] is for method " + other->name +
                                                   "; this file grows with method " + m.name + " ([tree] method)");
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

double declaredQuantity(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table,
                        const std::string& key, Dimension dim, double voxel_mm) {
  const char* fallback = fallbackOf(m, table, key);
  if (t.get(key) || !fallback) return r.quantity(t, table, key, dim, voxel_mm);
  return parseQuantity(fallback, dim, voxel_mm);
}

double declaredNumber(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table,
                      const std::string& key) {
  const char* fallback = fallbackOf(m, table, key);
  if (t.get(key) || !fallback) return r.number(t, table, key);
  return std::stod(fallback);
}

int declaredCount(const TomlReader& r, const GrowthMethod& m, const toml::table& t, const std::string& table,
                  const std::string& key, std::int64_t lo, std::int64_t hi) {
  const char* fallback = fallbackOf(m, table, key);
  if (t.get(key) || !fallback) return r.smallInteger(t, table, key, lo, hi);
  return std::stoi(fallback);
}

std::vector<MethodParam> withPhysicsParams(std::vector<MethodParam> rows, bool cost_exponents, const char* viscosity,
                                           const char* perfusion_pressure, const char* terminal_pressure,
                                           const char* perfusion_flow) {
  rows.push_back({"physics", "murray_exponent", "", "3", "γ in r_parent^γ = r_a^γ + r_b^γ"});
  if (cost_exponents) {
    rows.push_back({"physics", "cost_radius_exponent", "", "2", "λ of the cost Σ l^μ r^λ"});
    rows.push_back({"physics", "cost_length_exponent", "", "1", "μ of the cost Σ l^μ r^λ"});
  }
  rows.push_back({"physics", "viscosity", "Pa*s", viscosity, "blood viscosity η"});
  rows.push_back({"physics", "perfusion_pressure", "Pa", perfusion_pressure, "pressure at the root"});
  rows.push_back({"physics", "terminal_pressure", "Pa", terminal_pressure, "pressure at every terminal"});
  rows.push_back({"physics", "perfusion_flow", "mm^3/s", perfusion_flow, "flow into the root, split equally among the terminals"});
  return rows;
}

PhysicsParameters readPhysics(const TomlReader& r, const GrowthMethod& m, const toml::table& ph) {
  PhysicsParameters p;
  p.murray_exponent = declaredNumber(r, m, ph, "physics", "murray_exponent");
  checkRange(p.murray_exponent, Limits::kMinMurray, true, Limits::kMaxMurray, false, r.at(ph, "murray_exponent"), "murray_exponent");
  if (findParam(m, "physics", "cost_radius_exponent")) {
    p.cost_radius_exponent = declaredNumber(r, m, ph, "physics", "cost_radius_exponent");
    checkRange(p.cost_radius_exponent, 0, false, Limits::kMaxCostExponent, false, r.at(ph, "cost_radius_exponent"), "cost_radius_exponent");
    p.cost_length_exponent = declaredNumber(r, m, ph, "physics", "cost_length_exponent");
    checkRange(p.cost_length_exponent, 0, false, Limits::kMaxCostExponent, false, r.at(ph, "cost_length_exponent"), "cost_length_exponent");
  }
  p.viscosity = declaredQuantity(r, m, ph, "physics", "viscosity", Dimension::Viscosity);
  checkRange(p.viscosity, Limits::kMinViscosity, false, Limits::kMaxViscosity, false, r.at(ph, "viscosity"), "viscosity (Pa*s)");
  p.perfusion_pressure = declaredQuantity(r, m, ph, "physics", "perfusion_pressure", Dimension::Pressure);
  p.terminal_pressure = declaredQuantity(r, m, ph, "physics", "terminal_pressure", Dimension::Pressure);
  checkRange(p.terminal_pressure, 0, false, Limits::kMaxPressure, false, r.at(ph, "terminal_pressure"), "terminal_pressure (Pa)");
  checkRange(p.perfusion_pressure, 0, false, Limits::kMaxPressure, false, r.at(ph, "perfusion_pressure"), "perfusion_pressure (Pa)");
  if (!(p.perfusion_pressure - p.terminal_pressure >= Limits::kMinPressureDrop))
    throw InputError(r.file(), r.lineOf(ph.get("perfusion_pressure")), "perfusion_pressure must exceed terminal_pressure by at least 0.001 Pa");
  p.perfusion_flow = declaredQuantity(r, m, ph, "physics", "perfusion_flow", Dimension::Flow);
  checkRange(p.perfusion_flow, Limits::kMinFlow, false, Limits::kMaxFlow, false, r.at(ph, "perfusion_flow"), "perfusion_flow (mm^3/s)");
  return p;
}

std::optional<Vec3> readRoot(const TomlReader& r, const toml::table& tree, Vec3& root_voxel, int& root_line,
                             const std::string& voxels, const std::string& why_required, const std::string& table) {
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

std::int64_t readTerminals(const TomlReader& r, const toml::table& tree, int& line) {
  const std::int64_t n = r.integer(tree, "tree", "terminals");
  line = r.lineOf(tree.get("terminals"));
  checkRange(double(n), 1, false, Limits::kMaxTerminals, false, r.at(tree, "terminals"), "terminals");
  return n;
}

void describePhysics(const PhysicsParameters& p, std::int64_t terminals, nlohmann::ordered_json& j) {
  j["viscosity"] = quantityJson(p.viscosity, "Pa*s");
  j["perfusion_pressure"] = quantityJson(p.perfusion_pressure, "Pa");
  j["terminal_pressure"] = quantityJson(p.terminal_pressure, "Pa");
  j["perfusion_flow"] = quantityJson(p.perfusion_flow, "mm^3/s");
  j["terminal_flow"] = quantityJson(p.perfusion_flow / double(terminals), "mm^3/s");
}

}  // namespace angiosynth
