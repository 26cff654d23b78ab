// The native parameter format: TOML with units written out ("0.4 mm", "100 mmHg",
// "3.6 mPa*s", "8330 mm3/s"). Every key is checked; unknown keys are errors.
#include <algorithm>
#include <set>

#include "core/error.hpp"
#include "core/format.hpp"
#include "settings/param_checks.hpp"
#include "grow/method.hpp"
#include "config/sample_settings.hpp"
#include "config/scenario.hpp"
#include "settings/toml_reader.hpp"

namespace angiosynth {
namespace {

// Where a key of table `t` stands, for the rules between settings.
auto keysOf(const TomlReader& r, const toml::table& t) {
  return [&r, &t](const char* key) -> std::optional<Where> {
    if (t.get(key)) return r.at(t, key);
    return std::nullopt;
  };
}

// A table whose presence enables its stage ([mesh], [curves]): its settings and rules, and its line.
template <class Options>
void readEnablingTable(const TomlReader& r, const char* name, const std::vector<Setting<Options>>& settings,
                       const std::vector<SettingRule<Options>>& rules, Options& o, int& line, double voxel_mm) {
  const auto& t = r.table(name, settingKeys(settings));
  const auto* n = r.root().get(name);
  if (!n) return;
  line = r.lineOf(n);
  o.enabled = true;
  readSettings(r, name, settings, o, voxel_mm);
  checkRules(rules, o, keysOf(r, t), Where{r.file(), line});
}

template <class... Lists>
std::set<std::string> keysOfAll(const Lists&... lists) {
  std::set<std::string> keys;
  (keys.merge(settingKeys(lists)), ...);
  return keys;
}

}  // namespace

MeshParameters readMeshParameters(const toml::table& root, const std::filesystem::path& path, double voxel_mm) {
  TomlReader r(root, path.string());
  r.checkKeys(root, {"mesh"}, "the top level");
  Scenario sc;
  readEnablingTable(r, "mesh", meshSettings(), meshRules(), sc.mesh, sc.mesh_line, voxel_mm);
  sc.mesh.enabled = true;
  return sc.mesh;
}

Scenario readTomlParameters(const std::filesystem::path& path) { return readTomlParameters(parseTomlFile(path, "parameter file"), path); }

Scenario readTomlParameters(const toml::table& root, const std::filesystem::path& path) {
  const std::string file = path.string();
  TomlReader r(root, file);
  Scenario sc;
  sc.parameter_file = file;
  sc.format = "toml";
  if (const auto* s = root.get("seed")) {
    if (!s->is_integer() || *s->value<std::int64_t>() < 0) throw InputError(file, r.lineOf(s), "seed must be a whole number >= 0");
    sc.seed = static_cast<std::uint64_t>(*s->value<std::int64_t>());
  }

  // [tree] method chooses the reader of [domain], [tree] and [physics].
  std::string method = "vascusynth";
  const toml::node* method_node = nullptr;
  if (const auto* t = root.get("tree"); t && t->is_table() && t->as_table()->get("method")) {
    method_node = t->as_table()->get("method");
    method = r.string(*t->as_table(), "tree", "method");
  }
  const GrowthMethod* m = findGrowthMethod(method);
  if (!m) throw InputError(file, r.lineOf(method_node), "method '" + method + "' is not available; allowed: " + growthMethodNames());
  // The top-level tables: the common ones and those the method declares ([[stage]], [[region]]).
  std::set<std::string> top{"seed", "domain", "tree", "physics", "curves", "image", "degrade", "output", "mesh"};
  const auto tableOf = [](const MethodParam& p) { return std::string(p.table).substr(0, std::string(p.table).find('.')); };
  for (const auto& p : m->params) top.insert(tableOf(p));
  for (const auto& [k, v] : root) {
    if (top.count(std::string(k.str()))) continue;
    for (const auto* other : growthMethods())
      for (const auto& p : other->params)
        if (tableOf(p) == k.str())
          throw InputError(file, r.lineOf(&v), "[" + std::string(k.str()) + "] is for method " + other->name + ", not " + m->name);
  }
  r.checkKeys(root, top, "the top level");
  sc.growth = m->read(r, *m);
  const double voxel_mm = sc.growth->voxelMm();

  // [image]; [mesh] and [curves] (each table's presence enables its stage); [degrade]; [output].
  const auto& im = r.table("image", keysOfAll(imageSettings(), labelSettings()));
  sc.image_line = r.lineOf(root.get("image"));
  readSettings(r, "image", imageSettings(), sc.image, voxel_mm);
  readSettings(r, "image", labelSettings(), sc.image.labels, voxel_mm);
  checkRules(labelRules(), sc.image.labels, keysOf(r, im), Where{file, sc.image_line});

  readEnablingTable(r, "mesh", meshSettings(), meshRules(), sc.mesh, sc.mesh_line, voxel_mm);
  readEnablingTable(r, "curves", curveSettings(), curveRules(), sc.curves, sc.curves_line, voxel_mm);

  for (const char* table : {"degrade", "output"}) {
    r.table(table, settingKeys(outputSettings(), table));
    readSettings(r, table, outputSettings(), sc, voxel_mm);
  }
  sc.profiles_line = r.lineOf(r.tableOrEmpty("degrade").get("profiles"));
  sc.units_note = "all values carry their units in the parameter file; internal units are mm, mm^3/s, Pa, Pa*s";
  return sc;
}

}  // namespace angiosynth
