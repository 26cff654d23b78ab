// Method "cco": its parameters, TOML reader, description, domain and grow function.
#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "grow/cco/setup.hpp"
#include "grow/common/feasibility.hpp"
#include "grow/common/method_tables.hpp"
#include "io/growth_domain_files.hpp"
#include "io/map_files.hpp"
#include "io/scenario.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

class PreparedCco final : public PreparedGrowth {
 public:
  PreparedCco(const CcoSetup& s, GrowthDomain d) : setup_(s), domain_(std::move(d)) {}
  const DemandMap& frame() const override { return domain_.frame(); }
  void checkFeasibility() const override {
    ccoRoot(setup_, domain_);
    std::int64_t inside = 0;  // voxels of the domain
    for (float v : domain_.frame().demand) inside += v > 0;
    const auto& c = setup_.cco;
    // A terminal per voxel of the domain at most: finer than its resolution the mask says nothing.
    if (c.terminals > inside)
      throw InputError(setup_.parameter_file, setup_.terminals_line,
                       std::to_string(c.terminals) + " terminals exceed the " + std::to_string(inside) +
                           " voxels of the domain; use fewer terminals or a finer voxel_size (mask)");
    checkVesselRoom(c.physics, c.terminals, domain_.measure(), domain_.dimension(), setup_.parameter_file, setup_.terminals_line);
  }
  const GrowthDomain* domain() const override { return &domain_; }
  Forest grow(std::uint64_t seed, std::uint64_t sample, GrowthReport& report, const ProgressFn& progress) const override {
    CcoOptions co = setup_.cco;
    co.root_mm = ccoRoot(setup_, domain_);
    co.seed = seed;
    co.sample = sample;
    return singleTreeForest(growCco(domain_, co, report, progress));
  }
  void addStatistics(const GrowthReport& report, Json& stats) const override {
    stats["threshold_relaxations"] = report.threshold_relaxations;
    stats["neighbour_doublings"] = report.neighbour_doublings;
    stats["kamiya_failures"] = report.kamiya_failures;
    stats["short_segments"] = report.short_segments;
    stats["short_segments_definition"] = "segments not longer than twice their radius";
    stats["outside_segments"] = report.outside_segments;
    stats["domain_dimension"] = domain_.dimension();
    stats["domain_measure"] = quantityJson(domain_.measure(), domain_.dimension() == 2 ? "mm^2" : "mm^3");
  }

 private:
  const CcoSetup& setup_;
  GrowthDomain domain_;
};

std::shared_ptr<const GrowthSetup> readCcoToml(const TomlReader& r, const GrowthMethod& m) {
  auto s = std::make_shared<CcoSetup>();
  const std::string file = r.file();
  const std::filesystem::path path = file;
  s->parameter_file = file;
  if (const auto* ph = r.root().get("physics"); ph && ph->is_table())
    r.forbid(*ph->as_table(), "physics", {"cost_radius_exponent", "cost_length_exponent"},
             "is for method vascusynth; cco minimises the total volume (radius exponent 2, length exponent 1)");
  const auto& dom = methodTable(r, m, "domain");
  const auto& tree = methodTable(r, m, "tree");
  auto& d = s->domain;
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
    const bool nifti = isNifti(d.mask);
    if (nifti) {
      if (dom.get("voxel_size"))
        throw InputError(file, r.lineOf(dom.get("voxel_size")), "a NIfTI mask carries its voxel size; remove voxel_size");
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
    // A NIfTI mask's voxel size is known only once it is read: its root stays in mm until then.
    if (const auto mm = readRoot(r, tree, d.root_voxel, d.root_line, "mask voxels", ": a mask domain has no default root")) {
      if (nifti) {
        d.root_mm = *mm;
        d.root_in_mm = true;
      } else {
        d.root_voxel = *mm / d.voxel_mm;
      }
    }
  } else {
    r.forbid(dom, "domain", {"mask", "sampling"}, "is for shape = \"mask\"");
    r.forbid(tree, "tree", {"root", "root_voxel"}, "is for mask domains; an analytic shape takes root_offset (mm from its centre)");
    const char* size_key = round ? "radius" : "side";
    r.forbid(dom, "domain", {round ? "side" : "radius"}, std::string("does not size a ") + shape + "; give " + size_key);
    d.size_mm = r.quantity(dom, "domain", size_key, Dimension::Length);
    checkRange(d.size_mm, Limits::kMinVoxel, false, Limits::kMaxLength, false, r.at(dom, size_key), std::string(size_key) + " (mm)");
    d.voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
    checkRange(d.voxel_mm, std::max(Limits::kMinVoxel, d.size_mm / Limits::kMaxVoxelsPerAxis), false, d.size_mm, true,
               r.at(dom, "voxel_size"), "voxel_size (mm)");
    if (const auto* n = tree.get("root_offset")) {
      const bool flat = d.shape == DomainShape::Disc || d.shape == DomainShape::Square;
      d.root_offset_mm = r.point(n, "root_offset (mm from the centre)", flat);
      d.has_root_offset = true;
      d.root_line = r.lineOf(n);
    }
  }

  auto& c = s->cco;
  c.terminals = readTerminals(r, tree, s->terminals_line);
  const auto whole = [&](const char* key, int& out, int lo, int hi) { out = declaredCount(r, m, tree, "tree", key, lo, hi); };
  whole("closest_neighbours", c.closest_neighbours, 1, Limits::kMaxNeighbours);
  c.physics = readPhysics(r, m, methodTable(r, m, "physics"));
  c.physics.total_terminals = c.terminals;
  whole("max_closest_neighbours", c.max_neighbours, c.closest_neighbours, Limits::kMaxNeighbours * 64);
  c.max_neighbours = std::max(c.max_neighbours, c.closest_neighbours);
  whole("kamiya_iterations", c.kamiya_iterations, 1, 100000);
  whole("draws_before_relaxing", c.draws_before_relaxing, 1, 1000000);
  c.kamiya_tolerance = declaredNumber(r, m, tree, "tree", "kamiya_tolerance");
  checkRange(c.kamiya_tolerance, 0, true, 1, true, r.at(tree, "kamiya_tolerance"), "kamiya_tolerance");
  c.relaxation = declaredNumber(r, m, tree, "tree", "relaxation");
  checkRange(c.relaxation, 0, true, 1, true, r.at(tree, "relaxation"), "relaxation");
  return s;
}

}  // namespace

GrowthDomain loadCcoDomain(const CcoSetup& s, std::uint64_t limit) {
  const auto& spec = s.domain;
  if (spec.shape != DomainShape::Mask) {
    const auto n = GrowthDomain::analyticDims(spec.shape, spec.size_mm, spec.voxel_mm);
    checkDomainMemory(std::int64_t(n[0]) * n[1] * n[2], limit, s.parameter_file, spec.line,
                      std::string("a ") + domainShapeName(spec.shape) + " frame");
    return GrowthDomain::analytic(spec.shape, spec.size_mm, spec.voxel_mm);
  }
  DemandMap m;
  if (isNifti(spec.mask)) {
    m = readNiftiMask(spec.mask, limit);
  } else {  // a VascuSynth box map; checks the root too
    BoxMapSpec box;
    box.parameter_file = s.parameter_file;
    box.demand_map = spec.mask;
    box.supply_coefficients = {1, 0};
    box.voxel_mm = spec.voxel_mm;
    box.root_voxel = spec.root_voxel;
    box.root_line = spec.root_line;
    m = loadDomain(box, limit);
  }
  std::int64_t inside = 0;
  for (float v : m.demand) inside += v > 0;
  if (inside == 0) throw InputError(spec.mask.string(), 0, "the mask has no voxel > 0; nothing to perfuse");
  return GrowthDomain::mask(std::move(m), spec.demand_weighted);
}

Vec3 ccoRoot(const CcoSetup& s, const GrowthDomain& d) {
  const auto& spec = s.domain;
  Vec3 root;
  if (spec.shape != DomainShape::Mask) {
    root = spec.has_root_offset ? d.center() + spec.root_offset_mm : d.defaultRoot();
  } else {
    root = spec.root_in_mm ? spec.root_mm : d.frame().toMm(spec.root_voxel);
  }
  if (d.dimension() == 2) root.z = d.planeZ();
  // The root may sit on the border (where the vessel enters), not outside it.
  const double tolerance = d.frame().voxel_mm * 1e-6;
  if (d.depth(root) < -tolerance)
    throw InputError(s.parameter_file, spec.root_line,
                     "the root (" + show3(root) + " mm in the frame) lies outside the " + domainShapeName(d.shape()) +
                         " domain (" + show(-d.depth(root)) + " mm beyond its border); place it inside or on the border");
  return root;
}

Json CcoSetup::describe() const {
  const auto& d = domain;
  const auto& c = cco;
  Json j;
  j["method"] = "cco";
  j["shape"] = domainShapeName(d.shape);
  if (d.shape == DomainShape::Mask) {
    j["mask"] = d.mask.string();
    j["sampling"] = d.demand_weighted ? "demand" : "uniform";
    if (d.root_in_mm) j["root"] = Json{{"value", {d.root_mm.x, d.root_mm.y, d.root_mm.z}}, {"unit", "mm"}};
    else j["root_voxel"] = {d.root_voxel.x, d.root_voxel.y, d.root_voxel.z};
  } else {
    j[d.shape == DomainShape::Sphere || d.shape == DomainShape::Disc ? "radius" : "side"] = quantityJson(d.size_mm, "mm");
    j["root_offset"] = d.has_root_offset ? Json{{"value", {d.root_offset_mm.x, d.root_offset_mm.y, d.root_offset_mm.z}}, {"unit", "mm"}}
                                         : Json("the top of the domain (+y)");
  }
  if (d.voxel_mm > 0) j["voxel_size"] = quantityJson(d.voxel_mm, "mm");
  j["terminals"] = c.terminals;
  j["closest_neighbours"] = c.closest_neighbours;
  j["max_closest_neighbours"] = c.max_neighbours;
  j["kamiya_iterations"] = c.kamiya_iterations;
  j["kamiya_tolerance"] = c.kamiya_tolerance;
  j["draws_before_relaxing"] = c.draws_before_relaxing;
  j["relaxation"] = c.relaxation;
  j["murray_exponent"] = c.physics.murray_exponent;
  describePhysics(c.physics, c.terminals, j);
  return j;
}

std::vector<std::filesystem::path> CcoSetup::inputs() const {
  if (domain.mask.empty()) return {};
  return {domain.mask};
}

std::unique_ptr<PreparedGrowth> CcoSetup::prepare(std::uint64_t memory_limit) const {
  return std::make_unique<PreparedCco>(*this, loadCcoDomain(*this, memory_limit));
}

const GrowthMethod kCcoMethod{
    "cco",
    "constrained constructive optimisation (Karch 1999, OpenCCO; seed 000) in a sphere, cube, disc, square or mask: the "
    "domain grows with the tree, each terminal joins the one of its nearest segments whose Kamiya bifurcation gives the "
    "least total volume, no vessel leaves the domain or overlaps another",
    // Seed 000 §5 (Karch 1999): 3.6 cP, written in Pa*s, since "3.6 cP" parses one ulp off 3.6e-3.
    withPhysicsParams({
        {"domain", "shape", "text", "sphere", "sphere, cube, disc or square (2D), or mask"},
        {"domain", "radius", "mm", nullptr, "sphere and disc: the radius"},
        {"domain", "side", "mm", nullptr, "cube and square: the side"},
        {"domain", "mask", "file", nullptr, "shape = \"mask\": a NIfTI volume (voxels > 0 inside) or a VascuSynth box map"},
        {"domain", "sampling", "text", "uniform", "masks: terminals drawn uniformly, or ∝ the mask value (demand)"},
        {"domain", "voxel_size", "mm", nullptr, "the voxel of the frame (analytic shapes, box maps; a NIfTI mask carries its own)"},
        {"tree", "terminals", "count", nullptr, "N, the number of terminal segments"},
        {"tree", "root_offset", "[x, y(, z)] mm", "the top (+y)", "analytic shapes: the root relative to the centre"},
        {"tree", "root", "[x, y, z] mm", nullptr, "masks: the root in mm in the frame (or root_voxel)"},
        {"tree", "root_voxel", "[x, y, z] mask voxels", nullptr, "masks: the root in voxels (or root)"},
        {"tree", "closest_neighbours", "count", "20", "ν, the nearest segments tried per terminal"},
        {"tree", "max_closest_neighbours", "count", "80", "ν doubles up to this when every candidate fails"},
        {"tree", "kamiya_iterations", "count", "100", "iterations of Kamiya's bifurcation solver"},
        {"tree", "kamiya_tolerance", "", "1e-6", "its step, relative to the three lengths, at convergence"},
        {"tree", "draws_before_relaxing", "count", "100", "failed draws before the distance threshold shrinks"},
        {"tree", "relaxation", "", "0.9", "the factor on the distance threshold after such a run"},
    }, false, "0.0036 Pa*s", "100 mmHg", "60 mmHg", "500 mL/min"),
    &readCcoToml};

}  // namespace angiosynth
