#include "grow/common/domain_spec.hpp"

#include "core/quantity_json.hpp"

#include "core/error.hpp"
#include "grow/common/method_tables.hpp"
#include "io/growth_domain_files.hpp"
#include "io/map_files.hpp"
#include "settings/input_paths.hpp"

namespace angiosynth {

// The root of one tree from its table (`name`: "tree" or "tree.inlet"): root_offset for analytic
// shapes, root (mm) or root_voxel for masks.
RootSpec readRootOf(const TomlReader& r, const toml::table& t, const std::string& name, const DomainSpec& d, bool required) {
  RootSpec root;
  if (d.shape == DomainShape::Mask) {
    r.forbid(t, name, {"root_offset"}, "is for analytic shapes; give the root of a mask domain as root (mm) or root_voxel");
    // A NIfTI mask's voxel size is known only once it is read: its root stays in mm until then.
    if (const auto mm = readRoot(r, t, root.root_voxel, root.root_line, "mask voxels", ": a mask domain has no default root",
                                 name == "tree" ? name : "[" + name + "]")) {
      if (isNifti(d.mask)) {
        root.root_mm = *mm;
        root.root_in_mm = true;
      } else {
        root.root_voxel = *mm / d.voxel_mm;
      }
    }
    return root;
  }
  r.forbid(t, name, {"root", "root_voxel"}, "is for mask domains; an analytic shape takes root_offset (mm from its centre)");
  if (const auto* n = t.get("root_offset")) {
    const bool flat = d.shape == DomainShape::Disc || d.shape == DomainShape::Square;
    root.root_offset_mm = r.point(n, "root_offset (mm from the centre)", flat);
    root.has_root_offset = true;
    root.root_line = r.lineOf(n);
  } else if (required) {
    throw InputError(r.file(), r.lineOf(&t),
                     "missing key 'root_offset' (mm from the centre) in [[" + name + "]]: with several inlets each needs its own root");
  }
  return root;
}

MethodFileTables readMethodFileTables(const TomlReader& r, const GrowthMethod& m) {
  const auto& dom = methodTable(r, m, "domain");
  const auto& tree = methodTable(r, m, "tree");
  const auto& ph = methodTable(r, m, "physics");
  auto spec = readDomainSpec(r, dom, r.file());
  const bool flat = spec.shape == DomainShape::Disc || spec.shape == DomainShape::Square;
  return {dom, tree, ph, std::move(spec), flat};
}

// clang-format off
std::vector<MethodParam> withDomainParams(const char* shape_meaning, const char* sampling_meaning, std::vector<MethodParam> rows) {
  std::vector<MethodParam> out{
      {"domain", "shape", "text", "sphere", shape_meaning},
      {"domain", "radius", "mm", nullptr, "sphere and disc: the radius"},
      {"domain", "side", "mm", nullptr, "cube and square: the side"},
      {"domain", "mask", "file", nullptr, "shape = \"mask\": a NIfTI volume (voxels > 0 inside) or a VascuSynth box map"},
      {"domain", "sampling", "text", "uniform", sampling_meaning},
      {"domain", "voxel_size", "mm", nullptr, "the voxel of the frame (analytic shapes, box maps; a NIfTI mask carries its own)"},
  };
  const auto root_rows = [&](const char* table, const char* offset_default) {
    out.push_back({table, "root_offset", "[x, y(, z)] mm", offset_default, "analytic shapes: the root relative to the centre"});
    out.push_back({table, "root", "[x, y, z] mm", nullptr, "masks: the root in mm in the frame (or root_voxel)"});
    out.push_back({table, "root_voxel", "[x, y, z] mask voxels", nullptr, "masks: the root in voxels (or root)"});
  };
  // [tree]'s own rows first (terminals, where the method has them), then the root.
  std::size_t k = 0;
  for (; k < rows.size() && std::string(rows[k].table) == "tree" && std::string(rows[k].key) == "terminals"; ++k) out.push_back(rows[k]);
  root_rows("tree", "the top (+y)");
  out.insert(out.end(), rows.begin() + std::ptrdiff_t(k), rows.end());
  return out;
}
// clang-format on

std::vector<std::filesystem::path> domainInputs(const DomainSpec& spec) {
  if (spec.mask.empty()) return {};
  return {spec.mask};
}

DomainSpec readDomainSpec(const TomlReader& r, const toml::table& dom, const std::filesystem::path& path) {
  DomainSpec d;
  const std::string file = r.file();
  d.line = r.lineOf(&dom);
  const std::string shape = dom.get("shape") ? r.string(dom, "domain", "shape") : "sphere";
  const std::pair<const char*, DomainShape> shapes[] = {{"sphere", DomainShape::Sphere},
                                                        {"cube", DomainShape::Cube},
                                                        {"disc", DomainShape::Disc},
                                                        {"square", DomainShape::Square},
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
    d.mask = resolveInputPath(r.string(dom, "domain", "mask"), path, r.lineOf(dom.get("mask")));
    const bool nifti = isNifti(d.mask);
    if (nifti) {
      if (dom.get("voxel_size")) throw InputError(file, r.lineOf(dom.get("voxel_size")), "a NIfTI mask carries its voxel size; remove voxel_size");
    } else {
      d.voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
      checkRange(d.voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(dom, "voxel_size"), "voxel_size (mm)");
    }
    if (dom.get("sampling")) {
      const auto v = r.string(dom, "domain", "sampling");
      if (v != "uniform" && v != "demand")
        throw InputError(file, r.lineOf(dom.get("sampling")), "sampling '" + v + "'; allowed: uniform, demand (∝ mask value)");
      d.demand_weighted = v == "demand";
    }
  } else {
    r.forbid(dom, "domain", {"mask", "sampling"}, "is for shape = \"mask\"");
    const char* size_key = round ? "radius" : "side";
    r.forbid(dom, "domain", {round ? "side" : "radius"}, std::string("does not size a ") + shape + "; give " + size_key);
    d.size_mm = r.quantity(dom, "domain", size_key, Dimension::Length);
    checkRange(d.size_mm, Limits::kMinVoxel, false, Limits::kMaxLength, false, r.at(dom, size_key), std::string(size_key) + " (mm)");
    d.voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
    checkRange(d.voxel_mm, std::max(Limits::kMinVoxel, d.size_mm / Limits::kMaxVoxelsPerAxis), false, d.size_mm, true, r.at(dom, "voxel_size"),
               "voxel_size (mm)");
  }
  return d;
}

GrowthDomain loadDomainSpec(const DomainSpec& spec, const std::string& parameter_file, const RootSpec& root, std::uint64_t limit) {
  if (spec.shape != DomainShape::Mask) {
    const auto n = GrowthDomain::analyticDims(spec.shape, spec.size_mm, spec.voxel_mm);
    checkDomainMemory(std::int64_t(n[0]) * n[1] * n[2], limit, parameter_file, spec.line, std::string("a ") + domainShapeName(spec.shape) + " frame");
    return GrowthDomain::analytic(spec.shape, spec.size_mm, spec.voxel_mm);
  }
  DemandMap m;
  if (isNifti(spec.mask)) {
    m = readNiftiMask(spec.mask, limit);
  } else {  // a VascuSynth box map; checks the root too
    BoxMapSpec box;
    box.parameter_file = parameter_file;
    box.demand_map = spec.mask;
    box.supply_coefficients = {1, 0};
    box.voxel_mm = spec.voxel_mm;
    box.root_voxel = root.root_voxel;  // the others are checked by placeRoot
    box.root_line = root.root_line;
    m = loadDomain(box, limit);
  }
  std::int64_t inside = 0;
  for (float v : m.demand) inside += v > 0;
  if (inside == 0) throw InputError(spec.mask.string(), 0, "the mask has no voxel > 0; nothing to perfuse");
  return GrowthDomain::mask(std::move(m), spec.demand_weighted);
}

Vec3 placeRoot(const std::string& parameter_file, const RootSpec& spec, const GrowthDomain& d) {
  Vec3 root;
  if (d.shape() != DomainShape::Mask) {
    root = spec.has_root_offset ? d.center() + spec.root_offset_mm : d.defaultRoot();
  } else {
    root = spec.root_in_mm ? spec.root_mm : d.frame().toMm(spec.root_voxel);
  }
  if (d.dimension() == 2) root.z = d.planeZ();
  // The root may sit on the border (where the vessel enters), not outside it.
  const double tolerance = d.frame().voxel_mm * 1e-6;
  if (d.depth(root) < -tolerance)
    throw InputError(parameter_file, spec.root_line,
                     "the root (" + show3(root) + " mm in the frame) lies outside the " + domainShapeName(d.shape()) + " domain (" +
                         show(-d.depth(root)) + " mm beyond its border); place it inside or on the border");
  return root;
}

void describeDomainAndRoot(const DomainSpec& d, const RootSpec& root, nlohmann::ordered_json& j) {
  using Json = nlohmann::ordered_json;
  j["shape"] = domainShapeName(d.shape);
  if (d.shape == DomainShape::Mask) {
    j["mask"] = d.mask.string();
    if (root.root_in_mm)
      j["root"] = Json{{"value", {root.root_mm.x, root.root_mm.y, root.root_mm.z}}, {"unit", "mm"}};
    else
      j["root_voxel"] = {root.root_voxel.x, root.root_voxel.y, root.root_voxel.z};
  } else {
    j[d.shape == DomainShape::Sphere || d.shape == DomainShape::Disc ? "radius" : "side"] = quantityJson(d.size_mm, "mm");
    j["root_offset"] = root.has_root_offset ? Json{{"value", {root.root_offset_mm.x, root.root_offset_mm.y, root.root_offset_mm.z}}, {"unit", "mm"}}
                                            : Json("the top of the domain (+y)");
  }
  if (d.voxel_mm > 0) j["voxel_size"] = quantityJson(d.voxel_mm, "mm");
}

}  // namespace angiosynth
