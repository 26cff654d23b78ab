#include "grow/common/region_tables.hpp"

#include "settings/param_checks.hpp"
#include "settings/input_paths.hpp"

namespace angiosynth {

std::vector<std::string> regionNames(const TomlReader& r, const toml::table& t, const std::string& key, const std::set<std::string>& known) {
  std::vector<std::string> out;
  const auto* n = t.get(key);
  if (!n) return out;
  const auto* arr = n->as_array();
  if (!arr) {
    if (!n->is_string()) throw InputError(r.file(), r.lineOf(n), key + " must be a region name or an array of region names");
    out.push_back(*n->value<std::string>());
  } else {
    for (const auto& e : *arr) {
      if (!e.is_string()) throw InputError(r.file(), r.lineOf(n), key + " must hold region names (strings)");
      out.push_back(*e.value<std::string>());
    }
  }
  for (const auto& name : out)
    if (!known.count(name)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw InputError(r.file(), r.lineOf(n),
                       "region '" + name + "' in " + key + " is not defined; [[region]] names: " + (list.empty() ? "none" : list));
    }
  return out;
}

std::vector<RegionSpec> readRegions(const TomlReader& r, const GrowthMethod& m, bool flat) {
  std::vector<RegionSpec> out;
  const auto* list = r.root().get("region");
  if (!list) return out;
  const auto* arr = list->as_array();
  if (!arr || !arr->is_array_of_tables()) throw InputError(r.file(), r.lineOf(list), "region must be an array of tables: write each as [[region]]");
  std::set<std::string> seen;
  for (const auto& node : *arr) {
    const auto& t = *node.as_table();
    checkMethodKeys(r, m, t, "region");
    RegionSpec g;
    g.line = r.lineOf(&t);
    g.name = r.string(t, "region", "name");
    if (g.name.empty() || !seen.insert(g.name).second)
      throw InputError(r.file(), r.lineOf(t.get("name")), "region name '" + g.name + "' is empty or defined twice; names must be unique");
    g.shape = choice<RegionShape>(r, t, "region", "shape", flat ? RegionShape::Disc : RegionShape::Sphere,
                                  {{"sphere", RegionShape::Sphere},
                                   {"disc", RegionShape::Disc},
                                   {"shell", RegionShape::Shell},
                                   {"annulus", RegionShape::Annulus},
                                   {"box", RegionShape::Box}});
    const bool shape_flat = g.shape == RegionShape::Disc || g.shape == RegionShape::Annulus;
    if (flat != shape_flat && g.shape != RegionShape::Box)
      throw InputError(r.file(), r.lineOf(t.get("shape") ? t.get("shape") : &t),
                       std::string("region '") + g.name + "' is a " + regionShapeName(g.shape) + " in a " + (flat ? "2D" : "3D") +
                           " domain; allowed: " + (flat ? "disc, annulus, box" : "sphere, shell, box"));
    if (const auto* c = t.get("centre")) g.centre = r.point(c, "centre (mm from the domain's centre)", flat);
    const auto length = [&](const char* key) {
      const double v = r.quantity(t, "region", key, Dimension::Length);
      checkRange(v, 0, true, Limits::kMaxLength, false, r.at(t, key), std::string(key) + " (mm)");
      return v;
    };
    const auto only = [&](std::set<std::string> keys) {
      for (const char* k : {"radius", "inner_radius", "outer_radius", "size"})
        if (!keys.count(k) && t.get(k))
          throw InputError(r.file(), r.lineOf(t.get(k)), std::string("'") + k + "' does not size a " + regionShapeName(g.shape));
    };
    switch (g.shape) {
      case RegionShape::Sphere:
      case RegionShape::Disc:
        only({"radius"});
        g.radius = length("radius");
        break;
      case RegionShape::Shell:
      case RegionShape::Annulus:
        only({"inner_radius", "outer_radius"});
        g.inner = length("inner_radius");
        g.outer = length("outer_radius");
        if (!(g.outer > g.inner)) throw InputError(r.file(), r.lineOf(t.get("outer_radius")), "outer_radius must exceed inner_radius");
        break;
      case RegionShape::Box: {
        only({"size"});
        const auto* n = r.need(t, "region", "size");
        const auto v = r.point(n, "size ([x, y(, z)] mm)", flat);
        g.size = Vec3(v.x, v.y, flat ? 0.0 : v.z);
        if (!(g.size.x > 0 && g.size.y > 0 && (flat || g.size.z > 0))) throw InputError(r.file(), r.lineOf(n), "size must be positive on every axis");
        break;
      }
    }
    out.push_back(g);
  }
  return out;
}

InitialNetwork readInitialNetwork(const TomlReader& r, const GrowthMethod& m, const toml::node& node, bool flat) {
  const auto* t = node.as_table();
  if (!t) throw InputError(r.file(), r.lineOf(&node), "initial must be a table: [initial] file = \"tree.swc\"");
  checkMethodKeys(r, m, *t, "initial");
  InitialNetwork in;
  in.file = resolveInputPath(r.string(*t, "initial", "file"), r.file(), r.lineOf(t->get("file")));
  const auto unit = choice<double>(r, *t, "initial", "unit", 1.0, {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}, {"um", 1e-3}});
  in.from_corner = choice<bool>(r, *t, "initial", "origin", false, {{"centre", false}, {"corner", true}});
  in.network = readNetwork(in.file, unit);
  refuseLargeJunctions(in.network, in.file.string(), "growth from an initial network takes");
  if (flat) {
    const auto& t = in.network.tree;
    const double z0 = t.position.front().z;
    for (std::int32_t i = 0; i < t.nodeCount(); ++i)
      if (std::abs(t.position[i].z - z0) > 1e-9 * (1 + std::abs(z0)))
        throw InputError(in.file.string(), in.network.lines[std::size_t(i)],
                         "node " + (in.network.ids[std::size_t(i)].empty() ? std::to_string(i) : in.network.ids[std::size_t(i)]) +
                             " has z = " + show(t.position[i].z) + " mm where the first has " + show(z0) +
                             " mm; a 2D domain takes a network in one plane: allowed: every node at the same z");
  }
  return in;
}

// clang-format off
std::vector<MethodParam> withRegionParams(std::vector<MethodParam> rows, const char* used_by) {
  const std::vector<MethodParam> regions{
      {"region", "name", "text", nullptr, used_by},
      {"region", "shape", "text", "sphere (3D), disc (2D)", "sphere, shell, box (3D); disc, annulus, box (2D)"},
      {"region", "centre", "[x, y(, z)] mm", "[0, 0, 0]", "relative to the domain's centre"},
      {"region", "radius", "mm", nullptr, "sphere, disc"},
      {"region", "inner_radius", "mm", nullptr, "shell, annulus"},
      {"region", "outer_radius", "mm", nullptr, "shell, annulus"},
      {"region", "size", "[x, y(, z)] mm", nullptr, "box: its sides"},
  };
  rows.insert(rows.end(), regions.begin(), regions.end());
  return rows;
}
// clang-format on

}  // namespace angiosynth
