// The native parameter format: TOML with units written out ("0.4 mm", "100 mmHg",
// "3.6 mPa*s", "8330 mm3/s"). Every key is checked; unknown keys are errors.
#include "io/toml_file.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

#include "core/error.hpp"
#include "io/param_checks.hpp"
#include "io/scenario.hpp"

namespace angiosynth {
namespace {

class TomlReader {
 public:
  TomlReader(const toml::table& root, std::string file) : root_(root), file_(std::move(file)) {}

  int lineOf(const toml::node* n) const { return n ? static_cast<int>(n->source().begin.line) : 0; }

  const toml::table& table(const std::string& name, const std::set<std::string>& allowed) {
    const toml::node* n = root_.get(name);
    if (!n) {
      static const toml::table empty;
      return empty;
    }
    if (!n->is_table()) throw InputError(file_, lineOf(n), "[" + name + "] must be a table");
    const auto& t = *n->as_table();
    checkKeys(t, allowed, "[" + name + "]");
    return t;
  }

  void checkKeys(const toml::table& t, const std::set<std::string>& allowed, const std::string& where) {
    for (const auto& [k, v] : t) {
      if (allowed.count(std::string(k.str()))) continue;
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError(file_, lineOf(&v), "unknown key '" + std::string(k.str()) + "' in " + where + "; allowed: " + list);
    }
  }

  const toml::node* need(const toml::table& t, const std::string& section, const std::string& key) {
    const toml::node* n = t.get(key);
    if (!n) throw InputError(file_, lineOf(&t), "missing key '" + key + "' in [" + section + "]");
    return n;
  }

  double quantity(const toml::table& t, const std::string& section, const std::string& key, Dimension dim,
                  double voxel_mm = 0) {
    const toml::node* n = need(t, section, key);
    const auto s = n->value<std::string>();
    if (!s) throw InputError(file_, lineOf(n), key + " must be a string \"<number> <unit>\"; units: " + allowedUnits(dim));
    try {
      return parseQuantity(*s, dim, voxel_mm);
    } catch (const std::invalid_argument& e) {
      throw InputError(file_, lineOf(n), key + ": " + e.what());
    }
  }

  double number(const toml::table& t, const std::string& section, const std::string& key) {
    const toml::node* n = need(t, section, key);
    const auto v = n->value<double>();
    if (!v || n->is_string() || !std::isfinite(*v)) throw InputError(file_, lineOf(n), key + " must be a finite number");
    return *v;
  }

  std::int64_t integer(const toml::table& t, const std::string& section, const std::string& key) {
    const toml::node* n = need(t, section, key);
    if (!n->is_integer()) throw InputError(file_, lineOf(n), key + " must be a whole number");
    return *n->value<std::int64_t>();
  }

  // A whole number checked against [lo, hi] before it is narrowed.
  int smallInteger(const toml::table& t, const std::string& section, const std::string& key, std::int64_t lo, std::int64_t hi) {
    const std::int64_t v = integer(t, section, key);
    if (v < lo || v > hi)
      throw InputError(file_, lineOf(t.get(key)), key + " = " + std::to_string(v) + " is out of range; allowed: [" +
                                                      std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }

  std::string string(const toml::table& t, const std::string& section, const std::string& key) {
    const toml::node* n = need(t, section, key);
    const auto v = n->value<std::string>();
    if (!v) throw InputError(file_, lineOf(n), key + " must be a string");
    return *v;
  }

  std::vector<double> numbers(const toml::node* n, const std::string& key, std::size_t count) {
    const auto* arr = n->as_array();
    if (!arr || (count && arr->size() != count) || arr->empty())
      throw InputError(file_, lineOf(n), key + " must be an array of " + (count ? std::to_string(count) + " " : "") + "numbers");
    std::vector<double> out;
    for (const auto& e : *arr) {
      const auto v = e.value<double>();
      if (!v || e.is_string() || !std::isfinite(*v)) throw InputError(file_, lineOf(n), key + " must hold finite numbers only");
      out.push_back(*v);
    }
    return out;
  }

  // Keys that belong to another growth method.
  void forbid(const toml::table& t, const std::string& section, const std::set<std::string>& keys, const std::string& why) {
    for (const auto& k : keys)
      if (const auto* n = t.get(k)) throw InputError(file_, lineOf(n), "'" + k + "' in [" + section + "] " + why);
  }

  Vec3 point(const toml::node* n, const std::string& key, bool allow_2d) {
    const auto* arr = n->as_array();
    const std::size_t size = arr ? arr->size() : 0;
    if (!(size == 3 || (allow_2d && size == 2)))
      throw InputError(file_, lineOf(n), key + " must be an array of " + (allow_2d ? "2 or 3" : "3") + " numbers");
    const auto v = numbers(n, key, size);
    return Vec3(v[0], v[1], size == 3 ? v[2] : 0.0);
  }

  Where at(const toml::table& t, const std::string& key) const { return {file_, lineOf(t.get(key))}; }
  const std::string& file() const { return file_; }

 private:
  const toml::table& root_;
  std::string file_;
};

// The root from [tree]: root_voxel (`voxels`) goes to sc.root_voxel; root (mm) is returned.
// Exactly one of them is required.
std::optional<Vec3> readRoot(TomlReader& r, const toml::table& tree, Scenario& sc, const std::string& voxels,
                             const std::string& why_required) {
  if (tree.get("root_voxel") && tree.get("root"))
    throw InputError(r.file(), r.lineOf(tree.get("root")), "give root (mm) or root_voxel (" + voxels + "), not both");
  if (const auto* n = tree.get("root_voxel")) {
    sc.root_voxel = r.point(n, "root_voxel", false);
    sc.root_line = r.lineOf(n);
    return std::nullopt;
  }
  if (const auto* n = tree.get("root")) {
    sc.root_line = r.lineOf(n);
    return r.point(n, "root (mm)", false);
  }
  throw InputError(r.file(), r.lineOf(&tree), "missing key 'root' (mm) or 'root_voxel' (" + voxels + ") in [tree]" + why_required);
}

void readVascuSynthDomain(TomlReader& r, const toml::table& dom, const toml::table& tree, Scenario& sc,
                          const std::filesystem::path& path, const std::set<std::string>& cco_domain,
                          const std::set<std::string>& cco_tree) {
  const std::string file = path.string();
  r.forbid(dom, "domain", cco_domain, "is for method cco; this file grows with method vascusynth (set [tree] method = \"cco\")");
  r.forbid(tree, "tree", cco_tree, "is for method cco; this file grows with method vascusynth (set [tree] method = \"cco\")");
  auto& g = sc.growth;
  sc.voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
  checkRange(sc.voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(dom, "voxel_size"), "voxel_size (mm)");
  sc.demand_map = resolveInputPath(r.string(dom, "domain", "demand_map"), path, r.lineOf(dom.get("demand_map")));
  if (dom.get("supply_map") && dom.get("supply_coefficients"))
    throw InputError(file, r.lineOf(dom.get("supply_coefficients")), "give supply_map or supply_coefficients, not both");
  if (dom.get("supply_map")) {
    sc.supply_map = resolveInputPath(r.string(dom, "domain", "supply_map"), path, r.lineOf(dom.get("supply_map")));
    sc.supply_line = r.lineOf(dom.get("supply_map"));
  } else if (const auto* c = dom.get("supply_coefficients")) {
    sc.supply_coefficients = r.numbers(c, "supply_coefficients", 0);
    if (sc.supply_coefficients.back() < 0 || sc.supply_coefficients.back() > Limits::kMaxSupplyCutoff)
      throw InputError(file, r.lineOf(c), "supply_coefficients: the last value is the cut-off radius (map voxels); allowed: 0 to 1e6");
  }

  if (const auto mm = readRoot(r, tree, sc, "map voxels", "")) sc.root_voxel = *mm / sc.voxel_mm;
  g.min_distance_mm = tree.get("min_distance") ? r.quantity(tree, "tree", "min_distance", Dimension::Length, sc.voxel_mm) : sc.voxel_mm;
  checkRange(g.min_distance_mm, 0, false, Limits::kMaxLength, false, r.at(tree, "min_distance"), "min_distance (mm)");
  if (tree.get("min_segment_length")) {
    g.min_segment_length_mm = r.quantity(tree, "tree", "min_segment_length", Dimension::Length, sc.voxel_mm);
    checkRange(g.min_segment_length_mm, 0, true, Limits::kMaxLength, false, r.at(tree, "min_segment_length"), "min_segment_length (mm)");
  }
  if (const auto* n = tree.get("avoid_intersections")) {
    if (!n->is_boolean()) throw InputError(file, r.lineOf(n), "avoid_intersections must be true or false");
    g.avoid_intersections = *n->value<bool>();
  }

}

void readCcoDomain(TomlReader& r, const toml::table& dom, const toml::table& tree, Scenario& sc,
                   const std::filesystem::path& path, const std::set<std::string>& vs_domain,
                   const std::set<std::string>& vs_tree) {
  const std::string file = path.string();
  r.forbid(dom, "domain", vs_domain, "is for method vascusynth; for cco give shape = \"mask\" and mask = <file>");
  r.forbid(tree, "tree", vs_tree, "is for method vascusynth; cco keeps every segment longer than twice its radius");
  auto& d = sc.cco_domain;
  d.line = r.lineOf(&dom);
  const std::string shape = dom.get("shape") ? r.string(dom, "domain", "shape") : "sphere";
  const std::pair<const char*, DomainShape> shapes[] = {{"sphere", DomainShape::Sphere}, {"cube", DomainShape::Cube},
                                                        {"disc", DomainShape::Disc},     {"square", DomainShape::Square},
                                                        {"mask", DomainShape::Mask}};
  bool known = false;
  for (const auto& [name, value] : shapes)
    if (shape == name) {
      d.shape = value;
      known = true;
    }
  if (!known) throw InputError(file, r.lineOf(dom.get("shape")), "shape '" + shape + "'; allowed: sphere, cube, disc, square (2D), mask");
  const bool round = d.shape == DomainShape::Sphere || d.shape == DomainShape::Disc;
  if (d.shape == DomainShape::Mask) {
    r.forbid(dom, "domain", {"radius", "side"}, "is for analytic shapes; a mask's extent comes from its file");
    r.forbid(tree, "tree", {"root_offset"}, "is for analytic shapes; give the root of a mask domain as root (mm) or root_voxel");
    d.mask = resolveInputPath(r.string(dom, "domain", "mask"), path, r.lineOf(dom.get("mask")));
    const auto m = d.mask.string();
    const bool nifti = m.ends_with(".nii") || m.ends_with(".nii.gz");
    if (nifti) {
      if (dom.get("voxel_size"))
        throw InputError(file, r.lineOf(dom.get("voxel_size")), "a NIfTI mask carries its voxel size; remove voxel_size");
    } else {
      sc.voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
      checkRange(sc.voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(dom, "voxel_size"), "voxel_size (mm)");
      sc.demand_map = d.mask;  // a VascuSynth box map
      sc.supply_coefficients = {1, 0};
    }
    if (dom.get("sampling")) {
      const auto v = r.string(dom, "domain", "sampling");
      if (v != "uniform" && v != "demand")
        throw InputError(file, r.lineOf(dom.get("sampling")), "sampling '" + v + "'; allowed: uniform, demand (∝ mask value)");
      d.demand_weighted = v == "demand";
    }
    // A NIfTI mask's voxel size is known only once it is read: its root stays in mm until then.
    if (const auto mm = readRoot(r, tree, sc, "mask voxels", ": a mask domain has no default root")) {
      if (nifti) {
        d.root_mm = *mm;
        d.root_in_mm = true;
      } else {
        sc.root_voxel = *mm / sc.voxel_mm;
      }
    }
    return;
  }
  r.forbid(dom, "domain", {"mask", "sampling"}, "is for shape = \"mask\"");
  r.forbid(tree, "tree", {"root", "root_voxel"}, "is for mask domains; an analytic shape takes root_offset (mm from its centre)");
  const char* size_key = round ? "radius" : "side";
  r.forbid(dom, "domain", {round ? "side" : "radius"}, std::string("does not size a ") + shape + "; give " + size_key);
  d.size_mm = r.quantity(dom, "domain", size_key, Dimension::Length);
  checkRange(d.size_mm, Limits::kMinVoxel, false, Limits::kMaxLength, false, r.at(dom, size_key), std::string(size_key) + " (mm)");
  sc.voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
  checkRange(sc.voxel_mm, std::max(Limits::kMinVoxel, d.size_mm / Limits::kMaxVoxelsPerAxis), false, d.size_mm, true, r.at(dom, "voxel_size"), "voxel_size (mm)");
  if (const auto* n = tree.get("root_offset")) {
    const bool flat = d.shape == DomainShape::Disc || d.shape == DomainShape::Square;
    d.root_offset_mm = r.point(n, "root_offset (mm from the centre)", flat);
    d.has_root_offset = true;
    sc.root_line = r.lineOf(n);
  }
}

}  // namespace

Scenario readTomlParameters(const std::filesystem::path& path) {
  return readTomlParameters(parseTomlFile(path, "parameter file"), path);
}

Scenario readTomlParameters(const toml::table& root, const std::filesystem::path& path) {
  const std::string file = path.string();
  TomlReader r(root, file);
  r.checkKeys(root, {"seed", "domain", "tree", "physics", "image", "degrade", "output"}, "the top level");
  Scenario sc;
  sc.parameter_file = file;
  sc.format = "toml";
  if (const auto* s = root.get("seed")) {
    if (!s->is_integer() || *s->value<std::int64_t>() < 0)
      throw InputError(file, r.lineOf(s), "seed must be a whole number >= 0");
    sc.seed = static_cast<std::uint64_t>(*s->value<std::int64_t>());
  }

  // [tree] first: the growth method decides what [domain] and [physics] hold.
  const std::set<std::string> vascusynth_tree{"min_distance", "min_segment_length", "avoid_intersections"};
  const std::set<std::string> cco_tree{"root_offset", "max_closest_neighbours", "kamiya_iterations", "kamiya_tolerance",
                                       "draws_before_relaxing", "relaxation"};
  std::set<std::string> tree_keys{"method", "terminals", "root_voxel", "root", "closest_neighbours"};
  tree_keys.insert(vascusynth_tree.begin(), vascusynth_tree.end());
  tree_keys.insert(cco_tree.begin(), cco_tree.end());
  const auto& tree = r.table("tree", tree_keys);
  if (tree.get("method")) {
    sc.method = r.string(tree, "tree", "method");
    if (sc.method != "vascusynth" && sc.method != "cco")
      throw InputError(file, r.lineOf(tree.get("method")), "method '" + sc.method + "' is not available; allowed: vascusynth, cco");
  }
  const bool cco = sc.method == "cco";
  const std::set<std::string> cco_domain_keys{"shape", "radius", "side", "mask", "sampling"};
  const std::set<std::string> vs_domain_keys{"demand_map", "supply_map", "supply_coefficients"};
  std::set<std::string> domain_keys{"voxel_size"};
  domain_keys.insert(cco_domain_keys.begin(), cco_domain_keys.end());
  domain_keys.insert(vs_domain_keys.begin(), vs_domain_keys.end());
  const auto& dom = r.table("domain", domain_keys);
  if (cco) readCcoDomain(r, dom, tree, sc, path, vs_domain_keys, vascusynth_tree);
  else readVascuSynthDomain(r, dom, tree, sc, path, cco_domain_keys, cco_tree);

  auto& g = sc.growth;
  g.terminals = r.integer(tree, "tree", "terminals");
  sc.terminals_line = r.lineOf(tree.get("terminals"));
  checkRange(double(g.terminals), 1, false, Limits::kMaxTerminals, false, r.at(tree, "terminals"), "terminals");
  g.closest_neighbours = tree.get("closest_neighbours") ? r.smallInteger(tree, "tree", "closest_neighbours", 1, std::int64_t(Limits::kMaxNeighbours)) : (cco ? 20 : 5);

  const auto& ph = r.table("physics", {"murray_exponent", "cost_radius_exponent", "cost_length_exponent", "viscosity",
                                        "perfusion_pressure", "terminal_pressure", "perfusion_flow"});
  auto& p = g.physics;
  if (cco) r.forbid(ph, "physics", {"cost_radius_exponent", "cost_length_exponent"},
                    "is for method vascusynth; cco minimises the total volume (radius exponent 2, length exponent 1)");
  // Method cco defaults to seed 000 §5 (Karch 1999): 3.6 cP, 100 and 60 mmHg, 500 mL/min.
  const auto optional = [&](const char* key, Dimension dim, double fallback) {
    return (cco && !ph.get(key)) ? fallback : r.quantity(ph, "physics", key, dim);
  };
  p.murray_exponent = ph.get("murray_exponent") ? r.number(ph, "physics", "murray_exponent") : 3.0;
  checkRange(p.murray_exponent, Limits::kMinMurray, true, Limits::kMaxMurray, false, r.at(ph, "murray_exponent"), "murray_exponent");
  p.cost_radius_exponent = ph.get("cost_radius_exponent") ? r.number(ph, "physics", "cost_radius_exponent") : 2.0;
  checkRange(p.cost_radius_exponent, 0, false, Limits::kMaxCostExponent, false, r.at(ph, "cost_radius_exponent"), "cost_radius_exponent");
  p.cost_length_exponent = ph.get("cost_length_exponent") ? r.number(ph, "physics", "cost_length_exponent") : 1.0;
  checkRange(p.cost_length_exponent, 0, false, Limits::kMaxCostExponent, false, r.at(ph, "cost_length_exponent"), "cost_length_exponent");
  p.viscosity = optional("viscosity", Dimension::Viscosity, 3.6e-3);
  checkRange(p.viscosity, Limits::kMinViscosity, false, Limits::kMaxViscosity, false, r.at(ph, "viscosity"), "viscosity (Pa*s)");
  p.perfusion_pressure = optional("perfusion_pressure", Dimension::Pressure, 100 * 133.322387415);
  p.terminal_pressure = optional("terminal_pressure", Dimension::Pressure, 60 * 133.322387415);
  checkRange(p.terminal_pressure, 0, false, Limits::kMaxPressure, false, r.at(ph, "terminal_pressure"), "terminal_pressure (Pa)");
  checkRange(p.perfusion_pressure, 0, false, Limits::kMaxPressure, false, r.at(ph, "perfusion_pressure"), "perfusion_pressure (Pa)");
  if (!(p.perfusion_pressure - p.terminal_pressure >= Limits::kMinPressureDrop))
    throw InputError(file, r.lineOf(ph.get("perfusion_pressure")), "perfusion_pressure must exceed terminal_pressure by at least 0.001 Pa");
  p.perfusion_flow = optional("perfusion_flow", Dimension::Flow, 500 * 1e3 / 60);
  checkRange(p.perfusion_flow, Limits::kMinFlow, false, Limits::kMaxFlow, false, r.at(ph, "perfusion_flow"), "perfusion_flow (mm^3/s)");
  p.total_terminals = g.terminals;

  if (cco) {
    auto& c = sc.cco;
    c.terminals = g.terminals;
    c.physics = p;
    c.closest_neighbours = g.closest_neighbours;
    const auto whole = [&](const char* key, int& out, int lo, int hi) {
      if (tree.get(key)) out = r.smallInteger(tree, "tree", key, lo, hi);
    };
    whole("max_closest_neighbours", c.max_neighbours, c.closest_neighbours, Limits::kMaxNeighbours * 64);
    c.max_neighbours = std::max(c.max_neighbours, c.closest_neighbours);
    whole("kamiya_iterations", c.kamiya_iterations, 1, 100000);
    whole("draws_before_relaxing", c.draws_before_relaxing, 1, 1000000);
    if (tree.get("kamiya_tolerance")) {
      c.kamiya_tolerance = r.number(tree, "tree", "kamiya_tolerance");
      checkRange(c.kamiya_tolerance, 0, true, 1, true, r.at(tree, "kamiya_tolerance"), "kamiya_tolerance");
    }
    if (tree.get("relaxation")) {
      c.relaxation = r.number(tree, "tree", "relaxation");
      checkRange(c.relaxation, 0, true, 1, true, r.at(tree, "relaxation"), "relaxation");
    }
  }

  const auto& im = r.table("image", {"enabled", "voxel_size", "field_of_view", "supersampling", "background", "vessel",
                                     "dtype", "formats", "graph_formats"});
  auto& ip = sc.image;
  sc.image_line = r.lineOf(root.get("image"));
  if (const auto* n = im.get("enabled")) {
    if (!n->is_boolean()) throw InputError(file, r.lineOf(n), "enabled must be true or false");
    ip.enabled = *n->value<bool>();
  }
  if (im.get("voxel_size")) {
    ip.voxel_mm = r.quantity(im, "image", "voxel_size", Dimension::Length, sc.voxel_mm);
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
        f[ax] = parseQuantity(*v, Dimension::Length, sc.voxel_mm);
      } catch (const std::invalid_argument& e) {
        throw InputError(file, r.lineOf(n), std::string("field_of_view: ") + e.what());
      }
      checkRange(f[ax], 0, true, Limits::kMaxLength, false, r.at(im, "field_of_view"), "field_of_view (mm)");
    }
    ip.field_of_view_mm = Vec3(f[0], f[1], f[2]);
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
  const auto strings = [&](const char* key, const std::vector<std::string>& allowed) {
    const toml::node* n = im.get(key);
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
  if (im.get("formats")) ip.formats = strings("formats", {"nifti", "nrrd", "tiff", "png", "vdb"});
  if (im.get("graph_formats")) ip.graph_formats = strings("graph_formats", {"csv", "vtp", "swc", "graphml"});

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
