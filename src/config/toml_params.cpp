// The native parameter format: TOML with units written out ("0.4 mm", "100 mmHg",
// "3.6 mPa*s", "8330 mm3/s"). Every key is checked; unknown keys are errors.
#include <algorithm>
#include <set>

#include "core/error.hpp"
#include "core/format.hpp"
#include "settings/param_checks.hpp"
#include "grow/method.hpp"
#include "config/scenario.hpp"
#include "settings/toml_reader.hpp"
#include "io/graph_formats.hpp"
#include "io/mesh_writers.hpp"
#include "io/volume_formats.hpp"

namespace angiosynth {
namespace {

// [image] label_policy and its one parameter; a parameter of another policy is an error.
void readLabelPolicy(const TomlReader& r, const toml::table& im, ImageParameters& ip) {
  LabelPolicy& p = ip.labels;
  if (const auto* n = im.get("label_policy")) {
    p.name = r.string(im, "image", "label_policy");
    ip.labels_line = r.lineOf(n);
    const auto& names = labelPolicyNames();
    if (std::find(names.begin(), names.end(), p.name) == names.end())
      throw InputError(r.file(), r.lineOf(n), "label_policy '" + p.name + "'; allowed: binary, threshold, visible, soft, ignore");
  }
  const auto only = [&](const char* key, const char* policy) {
    if (im.get(key) && p.name != policy)
      throw InputError(r.file(), r.lineOf(im.get(key)), std::string(key) + " is a parameter of label_policy = \"" + policy +
                                                            "\", not of \"" + p.name + "\"; set that policy or remove the key");
    return im.get(key) != nullptr;
  };
  if (only("label_threshold", "threshold")) p.threshold = r.number(im, "image", "label_threshold");
  checkRange(p.threshold, 0, true, 1, false, r.at(im, "label_threshold"), "label_threshold (partial volume)");
  if (only("visible_snr", "visible")) p.visible_snr = r.number(im, "image", "visible_snr");
  checkRange(p.visible_snr, 0, false, 1000, false, r.at(im, "visible_snr"), "visible_snr (multiples of the noise sigma)");
  if (only("ignore_band", "ignore")) {
    const auto band = r.numbers(im.get("ignore_band"), "ignore_band", 2);
    if (!(band[0] >= 0 && band[0] < band[1] && band[1] <= 1))
      throw InputError(r.file(), r.lineOf(im.get("ignore_band")),
                       "ignore_band = [" + show(band[0]) + ", " + show(band[1]) + "]; allowed: [low, high] partial volumes with 0 <= low < high <= 1");
    p.ignore_low = band[0], p.ignore_high = band[1];
  }
}

}  // namespace

Scenario readTomlParameters(const std::filesystem::path& path) {
  return readTomlParameters(parseTomlFile(path, "parameter file"), path);
}

Scenario readTomlParameters(const toml::table& root, const std::filesystem::path& path) {
  const std::string file = path.string();
  TomlReader r(root, file);
  Scenario sc;
  sc.parameter_file = file;
  sc.format = "toml";
  if (const auto* s = root.get("seed")) {
    if (!s->is_integer() || *s->value<std::int64_t>() < 0)
      throw InputError(file, r.lineOf(s), "seed must be a whole number >= 0");
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

  const auto& im = r.table("image", {"enabled", "voxel_size", "field_of_view", "supersampling", "centerline_connectivity", "background", "vessel",
                                     "dtype", "formats", "graph_formats", "label_policy", "label_threshold", "visible_snr", "ignore_band"});
  auto& ip = sc.image;
  sc.image_line = r.lineOf(root.get("image"));
  ip.enabled = r.boolean(im, "enabled", ip.enabled);
  if (im.get("voxel_size")) {
    ip.voxel_mm = r.quantity(im, "image", "voxel_size", Dimension::Length, voxel_mm);
    checkRange(ip.voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(im, "voxel_size"), "image voxel_size (mm)");
  }
  if (const auto* n = im.get("field_of_view")) {
    const auto* arr = n->as_array();
    if (!arr || arr->size() != 3) throw InputError(file, r.lineOf(n), "field_of_view must be 3 lengths, e.g. [\"40 mm\", \"40 mm\", \"40 mm\"]");
    double f[3];
    for (int ax = 0; ax < 3; ++ax) {
      const auto v = (*arr)[ax].value<std::string>();
      if (!v) throw InputError(file, r.lineOf(n), "field_of_view must hold strings \"<number> <unit>\"");
      try {
        f[ax] = parseQuantity(*v, Dimension::Length, voxel_mm);
      } catch (const std::invalid_argument& e) {
        throw InputError(file, r.lineOf(n), std::string("field_of_view: ") + e.what());
      }
      checkRange(f[ax], 0, true, Limits::kMaxLength, false, r.at(im, "field_of_view"), "field_of_view (mm)");
    }
    ip.field_of_view_mm = Vec3(f[0], f[1], f[2]);
  }
  if (const auto* c = im.get("centerline_connectivity")) {
    ip.centerline_connectivity = int(r.smallInteger(im, "image", "centerline_connectivity", 6, 26));
    if (ip.centerline_connectivity != 6 && ip.centerline_connectivity != 26)
      throw InputError(file, r.lineOf(c), "centerline_connectivity = " + std::to_string(ip.centerline_connectivity) + "; allowed: 26 (a thin curve), 6 (face-connected)");
  }
  if (im.get("supersampling")) {
    ip.supersampling = r.smallInteger(im, "image", "supersampling", 1, 16);
  }
  if (im.get("background")) ip.background = r.number(im, "image", "background");
  if (im.get("vessel")) ip.vessel = r.number(im, "image", "vessel");
  checkRange(ip.background, -Limits::kMaxIntensity, false, Limits::kMaxIntensity, false, r.at(im, "background"), "background");
  checkRange(ip.vessel, -Limits::kMaxIntensity, false, Limits::kMaxIntensity, false, r.at(im, "vessel"), "vessel");
  if (im.get("dtype")) {
    ip.dtype = r.string(im, "image", "dtype");
    if (ip.dtype != "uint8" && ip.dtype != "uint16" && ip.dtype != "int16" && ip.dtype != "float32")
      throw InputError(file, r.lineOf(im.get("dtype")), "dtype '" + ip.dtype + "'; allowed: uint8, uint16, int16, float32");
  }
  const auto stringsOf = [&](const toml::table& table, const char* key, const std::vector<std::string>& allowed) {
    const toml::node* n = table.get(key);
    std::vector<std::string> out;
    const auto* arr = n->as_array();
    if (!arr) throw InputError(file, r.lineOf(n), std::string(key) + " must be an array of strings");
    for (const auto& e : *arr) {
      const auto v = e.value<std::string>();
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      if (!v || std::find(allowed.begin(), allowed.end(), *v) == allowed.end())
        throw InputError(file, r.lineOf(n), std::string(key) + ": '" + (v ? *v : "?") + "' is not a format; allowed: " + list);
      out.push_back(*v);
    }
    return out;
  };
  readLabelPolicy(r, im, ip);
  if (im.get("formats")) ip.formats = stringsOf(im, "formats", volumeFormatNames());
  if (im.get("graph_formats")) ip.graph_formats = stringsOf(im, "graph_formats", graphFormatNames());

  // [mesh]: the vessels' surface beside the graphs (src/mesh); the table's presence enables it.
  const auto& me = r.table("mesh", settingKeys(meshSettings()));
  if (const auto* n = root.get("mesh")) {
    sc.mesh_line = r.lineOf(n);
    sc.mesh.enabled = true;
    readSettings(r, me, meshSettings(), sc.mesh, voxel_mm);
    checkRules(meshRules(), sc.mesh, [&](const char* key) -> std::optional<Where> {
      if (me.get(key)) return r.at(me, key);
      return std::nullopt;
    }, Where{file, sc.mesh_line});
  }

  if (root.get("curves")) {
    const auto& cv = r.table("curves", {"tortuosity", "tortuosity_sd", "wavelength", "wavelength_radii", "piece_length", "wall_clearance",
                                        "avoid_overlaps"});
    auto& co = sc.curves;
    co.enabled = true;
    sc.curves_line = r.lineOf(root.get("curves"));
    if (cv.get("tortuosity")) co.tortuosity = r.number(cv, "curves", "tortuosity");
    checkRange(co.tortuosity, 1, false, 3, false, r.at(cv, "tortuosity"), "tortuosity (arc length over chord)");
    if (cv.get("tortuosity_sd")) co.tortuosity_sd = r.number(cv, "curves", "tortuosity_sd");
    checkRange(co.tortuosity_sd, 0, false, 1, false, r.at(cv, "tortuosity_sd"), "tortuosity_sd");
    if (cv.get("wavelength") && cv.get("wavelength_radii"))
      throw InputError(file, r.lineOf(cv.get("wavelength_radii")), "give wavelength (a length) or wavelength_radii (multiples of each vessel's radius), not both");
    if (cv.get("wavelength")) {
      co.wavelength_mm = r.quantity(cv, "curves", "wavelength", Dimension::Length, voxel_mm);
      checkRange(co.wavelength_mm, 0, true, Limits::kMaxLength, false, r.at(cv, "wavelength"), "wavelength (mm)");
    }
    if (cv.get("wavelength_radii")) co.wavelength_radii = r.number(cv, "curves", "wavelength_radii");
    checkRange(co.wavelength_radii, 2, false, 1e4, false, r.at(cv, "wavelength_radii"), "wavelength_radii");
    if (cv.get("piece_length")) {
      co.piece_mm = r.quantity(cv, "curves", "piece_length", Dimension::Length, voxel_mm);
      checkRange(co.piece_mm, Limits::kMinVoxel, false, Limits::kMaxLength, false, r.at(cv, "piece_length"), "piece_length (mm)");
    }
    if (cv.get("wall_clearance")) {
      co.wall_clearance_mm = r.quantity(cv, "curves", "wall_clearance", Dimension::Length, voxel_mm);
      checkRange(co.wall_clearance_mm, 0, false, Limits::kMaxLength, false, r.at(cv, "wall_clearance"), "wall_clearance (mm)");
    }
    co.avoid_overlaps = r.boolean(cv, "avoid_overlaps", co.avoid_overlaps);
  }

  const auto& deg = r.table("degrade", {"profiles"});
  if (const auto* n = deg.get("profiles")) {
    sc.profiles_line = r.lineOf(n);
    const auto* arr = n->as_array();
    if (!arr) throw InputError(file, r.lineOf(n), "profiles must be an array of profile names or files, e.g. [\"clean\", \"cta\"]");
    for (const auto& e : *arr) {
      const auto v = e.value<std::string>();
      if (!v || v->empty()) throw InputError(file, r.lineOf(n), "profiles must hold names (\"cta\") or paths to .toml profiles or VascuSynth noise files");
      sc.profiles.push_back(*v);
    }
  }

  const auto& out = r.table("output", {"gxl_dialect"});
  if (out.get("gxl_dialect")) {
    sc.gxl_dialect = r.string(out, "output", "gxl_dialect");
    if (sc.gxl_dialect != "gxl" && sc.gxl_dialect != "vascusynth")
      throw InputError(file, r.lineOf(out.get("gxl_dialect")), "gxl_dialect '" + sc.gxl_dialect + "'; allowed: gxl, vascusynth");
  }
  sc.units_note = "all values carry their units in the parameter file; internal units are mm, mm^3/s, Pa, Pa*s";
  return sc;
}

}  // namespace angiosynth
