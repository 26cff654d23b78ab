// Method "lsystem": its parameters, TOML reader, description and grow function.
#include <chrono>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "grow/common/chain_trees.hpp"
#include "grow/common/intersections.hpp"
#include "grow/common/method_tables.hpp"
#include "grow/common/region_tables.hpp"
#include "grow/lsystem/setup.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// The block and its vessels with room around them: vessels are rasterised unclipped.
double marginMm(const LsystemSetup& s) {
  const auto& p = s.lzh;
  return std::max(p.start_diameter / 2 + p.start_wall, p.capillary_diameter / 2 + p.capillary_wall) + 2 * s.voxel_mm;
}

class PreparedLsystem final : public PreparedGrowth {
 public:
  explicit PreparedLsystem(const LsystemSetup& s) : setup_(s) {
    const auto& p = s.lzh;
    const double m = marginMm(s);
    frame_.voxel_mm = s.voxel_mm;
    const auto voxels = [&](double mm) { return std::int32_t(std::ceil((mm + 2 * m) / s.voxel_mm - 1e-9)); };
    frame_.dims = {voxels(p.block_width), p.dimension == 3 ? voxels(p.block_width) : voxels(p.height), p.dimension == 3 ? voxels(p.height) : 1};
    corner_ = Vec3(m, m, p.dimension == 3 ? m : s.voxel_mm / 2);
  }
  const DemandMap& frame() const override { return frame_; }
  void checkFeasibility() const override {}  // the plan was solved and checked when the file was read
  Forest grow(std::uint64_t, std::uint64_t, GrowthReport& report, const ProgressFn& progress) const override {
    Forest f = buildLzhNetwork(setup_.lzh, setup_.plan, corner_, corner_.z);
    // Overlaps within the arterial and the venous tree, each vessel as a capsule of its larger
    // radius; capillaries keep their spacing by construction (checked when the file was read).
    report.intersecting_pairs = 0;
    const auto roots = f.vessels.roots();
    for (std::size_t k : {std::size_t(0), roots.size() - 1}) {
      VascularTree t;
      const auto begin = roots[k], end = k + 1 < roots.size() ? roots[k + 1] : f.vessels.nodeCount();
      for (auto i = begin; i < end; ++i) {
        t.addNode(f.vessels.position[i], f.vessels.parent[i] >= 0 ? f.vessels.parent[i] - begin : -1);
        t.radius[i - begin] = f.vessels.maxRadius(i);
      }
      const Vec3 hi = Vec3(frame_.dims[0], frame_.dims[1], frame_.dims[2]) * frame_.voxel_mm;
      report.intersecting_pairs += std::int64_t(intersectingPairs(t, Vec3(0, 0, 0), hi).size());
    }
    report.root_radius_mm = setup_.lzh.start_diameter / 2;
    if (progress) progress(1, 1);
    return f;
  }
  void addStatistics(const GrowthReport&, Json& stats) const override {
    const auto& plan = setup_.plan;
    stats["levels"] = plan.levels;
    stats["levels_per_plane"] = plan.levels_2d;
    stats["theta"] = quantityJson(plan.theta * 180 / std::numbers::pi, "deg");
    stats["capillaries"] = plan.leaves;
    stats["capillary_grid"] = setup_.lzh.dimension == 3 ? Json::array({std::int64_t(1) << plan.levels_2d, std::int64_t(1) << plan.levels_2d})
                                                         : Json::array({std::int64_t(1) << plan.levels_2d});
    stats["capillary_pitch"] = quantityJson(plan.leaf_spacing, "mm");
    stats["capillary_span"] = quantityJson(plan.leaf_span, "mm");
    stats["middle_tree_height"] = quantityJson(plan.middle_height, "mm");
    stats["level_lengths"] = Json{{"value", plan.length}, {"unit", "mm"}};
    stats["level_offsets"] = Json{{"value", plan.offset}, {"unit", "mm"}};
    stats["segments_per_path"] = 3 + 2 * plan.levels;
    stats["nodes_per_path"] = 4 + 2 * plan.levels;
  }

 private:
  const LsystemSetup& setup_;
  DemandMap frame_;
  Vec3 corner_;
};

// The keys only one mode reads: a key of the other mode is an error naming it.
const std::vector<std::pair<const char*, const char*>>& grammarOnlyKeys() {
  static const std::vector<std::pair<const char*, const char*>> keys{
      {"domain", "shape"}, {"domain", "radius"}, {"domain", "side"}, {"domain", "mask"}, {"tree", "root_offset"}, {"tree", "root"},
      {"tree", "root_voxel"}, {"tree", "direction"}, {"tree", "iterations"}, {"tree", "root_diameter"}, {"tree", "length_ratio"},
      {"tree", "length_margin"}, {"tree", "diameter_sd"}, {"tree", "radii"}, {"tree", "radius_ratio"}, {"tree", "angles"},
      {"tree", "branch_angle"}, {"tree", "angle_sd"}, {"tree", "roll_angle"}, {"tree", "roll_sd"}, {"tree", "stem_segments"},
      {"tree", "stem_angle"}, {"tree", "avoid_collisions"}, {"tree", "wall_clearance"}, {"tree", "tries"}, {"tree", "min_tip_fraction"},
      {"physics", "murray_exponent"}};
  return keys;
}

void forbidOtherModeKeys(const TomlReader& r, const GrowthMethod& m, bool grammar,
                         const std::vector<std::pair<const char*, const toml::table*>>& tables) {
  for (const auto& [name, t] : tables)
    for (const auto& p : m.params) {
      if (std::string(p.table) != name || !t->get(p.key)) continue;
      bool grammar_key = false;
      for (const auto& [tb, key] : grammarOnlyKeys()) grammar_key = grammar_key || (std::string(tb) == name && std::string(key) == p.key);
      const bool shared = std::string(p.key) == "mode" || std::string(p.key) == "voxel_size" || std::string(name) == "physics";
      if (shared && !grammar_key) continue;
      if (grammar_key != grammar)
        throw InputError(r.file(), r.lineOf(t->get(p.key)),
                         "'" + std::string(p.key) + "' in [" + name + "] is for mode " + (grammar_key ? "grammar" : "lzh") + "; this file's mode is " +
                             (grammar ? "grammar" : "lzh") + " ([tree] mode)");
    }
}

void readPhysicsRows(const TomlReader& r, const GrowthMethod& m, const toml::table& ph, PhysicsParameters& phys) {
  phys.viscosity = declaredQuantity(r, m, ph, "physics", "viscosity", Dimension::Viscosity);
  checkRange(phys.viscosity, Limits::kMinViscosity, false, Limits::kMaxViscosity, false, r.at(ph, "viscosity"), "viscosity (Pa*s)");
  phys.perfusion_pressure = declaredQuantity(r, m, ph, "physics", "perfusion_pressure", Dimension::Pressure);
  checkRange(phys.perfusion_pressure, 0, false, Limits::kMaxPressure, false, r.at(ph, "perfusion_pressure"), "perfusion_pressure (Pa)");
  phys.perfusion_flow = declaredQuantity(r, m, ph, "physics", "perfusion_flow", Dimension::Flow);
  checkRange(phys.perfusion_flow, Limits::kMinFlow, false, Limits::kMaxFlow, false, r.at(ph, "perfusion_flow"), "perfusion_flow (mm^3/s)");
  phys.murray_exponent = declaredNumber(r, m, ph, "physics", "murray_exponent");
  checkRange(phys.murray_exponent, Limits::kMinMurray, true, Limits::kMaxMurray, false, r.at(ph, "murray_exponent"), "murray_exponent");
}

void readGrammar(const TomlReader& r, const GrowthMethod& m, const toml::table& dom, const toml::table& tree, LsystemSetup& s) {
  s.domain = readDomainSpec(r, dom, s.parameter_file);
  const bool flat = s.domain.shape == DomainShape::Disc || s.domain.shape == DomainShape::Square;
  s.root = readRootOf(r, tree, "tree", s.domain, false);
  if (const auto* d = tree.get("direction")) {
    s.direction = r.point(d, "direction", flat);
    if (!(norm(s.direction) > 0)) throw InputError(r.file(), r.lineOf(d), "direction must not be zero");
    s.has_direction = true;
  }
  s.voxel_mm = s.domain.voxel_mm;
  auto& g = s.grammar_options;
  g.iterations = declaredCount(r, m, tree, "tree", "iterations", 0, 20);
  if (tree.get("root_diameter")) {
    s.root_diameter_mm = r.quantity(tree, "tree", "root_diameter", Dimension::Length, s.voxel_mm);
    checkRange(s.root_diameter_mm, 2 * Limits::kMinRadius, false, 2 * Limits::kMaxRadius, false, r.at(tree, "root_diameter"), "root_diameter (mm)");
  }
  const auto number = [&](const char* key, double lo, bool lo_open, double hi, bool hi_open) {
    const double v = declaredNumber(r, m, tree, "tree", key);
    checkRange(v, lo, lo_open, hi, hi_open, r.at(tree, key), key);
    return v;
  };
  g.length_ratio = number("length_ratio", 0, true, 1e4, false);
  g.length_margin = number("length_margin", 0, false, 1, true);
  g.diameter_sd = number("diameter_sd", 0, false, 10, false);
  g.murray = choice<bool>(r, tree, "tree", "radii", true, {{"murray", true}, {"ratio", false}});
  g.radius_ratio = number("radius_ratio", 0, true, 1, true);
  g.zamir_angles = choice<bool>(r, tree, "tree", "angles", true, {{"zamir", true}, {"fixed", false}});
  g.branch_angle = number("branch_angle", 0, false, 90, false);
  g.angle_sd = number("angle_sd", 0, false, 90, false);
  g.roll_angle = number("roll_angle", -360, false, 360, false);
  g.roll_sd = number("roll_sd", 0, false, 360, false);
  g.stem_segments = declaredCount(r, m, tree, "tree", "stem_segments", 1, 100);
  g.stem_angle = number("stem_angle", 0, false, 90, true);
  g.avoid_collisions = r.boolean(tree, "avoid_collisions", true);
  g.wall_clearance = declaredQuantity(r, m, tree, "tree", "wall_clearance", Dimension::Length, s.voxel_mm);
  checkRange(g.wall_clearance, 0, false, Limits::kMaxLength, false, r.at(tree, "wall_clearance"), "wall_clearance (mm)");
  g.tries = declaredCount(r, m, tree, "tree", "tries", 1, 1000);
  g.min_tip_fraction = number("min_tip_fraction", 0, false, 1, false);
  g.murray_exponent = s.physics_summary.murray_exponent;
  s.physics_summary.total_terminals = std::int64_t(1) << g.iterations;
}

// Mode grammar: the stochastic grammar grown in the domain from its root.
class PreparedGrammar final : public PreparedGrowth {
 public:
  PreparedGrammar(const LsystemSetup& s, GrowthDomain loaded) : setup_(s), loaded_(std::move(loaded)) {
    options_ = s.grammar_options;
    options_.domain = &loaded_;
    options_.root = placeRoot(s.parameter_file, s.root, loaded_);
    Vec3 d = s.has_direction ? s.direction : loaded_.center() - options_.root;
    if (loaded_.dimension() == 2) d.z = 0;
    if (!(norm(d) > 0)) d = Vec3(0, -1, 0);
    options_.direction = d / norm(d);
    options_.root_diameter = s.root_diameter_mm > 0 ? s.root_diameter_mm : s.root_diameter_fraction * diameterOf(loaded_);
  }
  const DemandMap& frame() const override { return loaded_.frame(); }
  void checkFeasibility() const override {}
  const GrowthDomain* domain() const override { return &loaded_; }
  Forest grow(std::uint64_t seed, std::uint64_t sample, GrowthReport& report, const ProgressFn& progress) const override {
    auto o = options_;
    o.seed = seed;
    o.sample = sample;
    gr_ = GrammarReport{};
    VascularTree t;
    try {
      t = growGrammar(o, gr_, progress);
    } catch (const GrowthError& e) {
      throw InputError(setup_.parameter_file, setup_.tree_line, e.what());
    }
    flowsAndPressures(t, setup_.physics_summary, gr_.tips > 0 ? setup_.physics_summary.perfusion_flow / double(gr_.tips) : 0.0);
    const auto t0 = std::chrono::steady_clock::now();
    report.intersecting_pairs = std::int64_t(crossingPairs(t).size());
    check_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    report.root_radius_mm = o.root_diameter / 2;
    return singleTreeForest(std::move(t));
  }
  void addStatistics(const GrowthReport&, Json& stats) const override {
    stats["root_diameter"] = quantityJson(options_.root_diameter, "mm");
    stats["tips_asked"] = gr_.asked_tips;
    stats["tips"] = gr_.tips;
    stats["stems_redrawn"] = gr_.redrawn;
    stats["branches_dropped_outside"] = gr_.dropped_outside;
    stats["branches_dropped_collision"] = gr_.dropped_collision;
    stats["timing_seconds"] = Json{{"crossing_check", check_seconds_}};  // a time: not sample data
    stats["intersecting_pairs_note"] = "lsystem: segments whose capsules overlap, unless the path between them along the tree is shorter than their radii";
  }

 private:
  const LsystemSetup& setup_;
  GrowthDomain loaded_;
  GrammarOptions options_;
  mutable GrammarReport gr_;
  mutable double check_seconds_ = 0;
};

std::shared_ptr<const GrowthSetup> readLsystemToml(const TomlReader& r, const GrowthMethod& m) {
  auto s = std::make_shared<LsystemSetup>();
  s->parameter_file = r.file();
  const auto& dom = methodTable(r, m, "domain");
  const auto& tree = methodTable(r, m, "tree");
  const auto& ph = methodTable(r, m, "physics");
  s->tree_line = r.lineOf(&tree);
  s->grammar = choice<bool>(r, tree, "tree", "mode", false, {{"lzh", false}, {"grammar", true}});
  forbidOtherModeKeys(r, m, s->grammar, {{"domain", &dom}, {"tree", &tree}, {"physics", &ph}});
  readPhysicsRows(r, m, ph, s->physics_summary);
  if (s->grammar) {
    readGrammar(r, m, dom, tree, *s);
    return s;
  }
  s->voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
  checkRange(s->voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(dom, "voxel_size"), "voxel_size (mm)");
  auto& p = s->lzh;
  p.dimension = declaredCount(r, m, tree, "tree", "dimension", 2, 3);
  const auto length = [&](const char* key) {
    const double v = declaredQuantity(r, m, tree, "tree", key, Dimension::Length, s->voxel_mm);
    checkRange(v, 0, true, Limits::kMaxLength, false, r.at(tree, key), std::string(key) + " (mm)");
    return v;
  };
  p.block_width = length("block_width");
  p.height = length("block_height");
  p.start_length = length("start_length");
  p.capillary_length = length("capillary_length");
  p.start_diameter = length("start_diameter");
  p.capillary_diameter = length("capillary_diameter");
  p.spacing = length("capillary_spacing");
  for (const char* key : {"start_wall", "capillary_wall"}) {
    const double v = declaredQuantity(r, m, tree, "tree", key, Dimension::Length, s->voxel_mm);
    checkRange(v, 0, false, Limits::kMaxLength, false, r.at(tree, key), std::string(key) + " (mm)");
    (std::string(key) == "start_wall" ? p.start_wall : p.capillary_wall) = v;
  }
  p.printed_level_rule = choice<bool>(r, tree, "tree", "level_rule", false, {{"corrected", false}, {"printed", true}});
  auto& phys = s->physics_summary;
  p.viscosity = phys.viscosity;
  p.perfusion_pressure = phys.perfusion_pressure;
  p.perfusion_flow = phys.perfusion_flow;
  try {
    s->plan = planLzh(p);
  } catch (const LzhError& e) {
    throw InputError(r.file(), tree.get(e.key) ? r.lineOf(tree.get(e.key)) : r.lineOf(&tree), e.what());
  }
  phys.total_terminals = s->plan.leaves;
  // The outlet's pressure follows from the inflow and the resistances (checked non-negative).
  const Forest f = buildLzhNetwork(p, s->plan, Vec3(0, 0, 0));
  phys.terminal_pressure = f.vessels.pressure[f.vessels.roots().back()];
  if (!(phys.terminal_pressure >= 0))
    throw InputError(r.file(), r.lineOf(ph.get("perfusion_flow") ? ph.get("perfusion_flow") : &ph),
                     "perfusion_flow " + std::to_string(phys.perfusion_flow) + " mm^3/s needs more than the inlet's perfusion_pressure (" +
                         std::to_string(phys.perfusion_pressure) + " Pa) to pass the network: the outlet would be at " +
                         std::to_string(phys.terminal_pressure) + " Pa; lower the flow or widen the vessels");
  return s;
}

// Both modes drive the network from its inlet with a given pressure and flow.
void describeInflow(const PhysicsParameters& p, Json& j) {
  j["viscosity"] = quantityJson(p.viscosity, "Pa*s");
  j["perfusion_pressure"] = quantityJson(p.perfusion_pressure, "Pa");
  j["perfusion_flow"] = quantityJson(p.perfusion_flow, "mm^3/s");
}

}  // namespace

Json LsystemSetup::describe() const {
  const auto& p = lzh;
  Json j;
  j["method"] = "lsystem";
  if (grammar) {
    const auto& g = grammar_options;
    j["mode"] = "grammar";
    describeDomainAndRoot(domain, root, j);
    if (has_direction) j["direction"] = {direction.x, direction.y, direction.z};
    j["iterations"] = g.iterations;
    j["root_diameter"] = root_diameter_mm > 0 ? quantityJson(root_diameter_mm, "mm") : Json{{"value", root_diameter_fraction}, {"unit", "domain diameter"}};
    j["length_ratio"] = g.length_ratio;
    j["length_margin"] = g.length_margin;
    j["diameter_sd"] = g.diameter_sd;
    j["radii"] = g.murray ? "murray" : "ratio";
    if (!g.murray) j["radius_ratio"] = g.radius_ratio;
    j["angles"] = g.zamir_angles ? "zamir" : "fixed";
    if (!g.zamir_angles) j["branch_angle"] = quantityJson(g.branch_angle, "deg");
    j["angle_sd"] = quantityJson(g.angle_sd, "deg");
    j["roll_angle"] = quantityJson(g.roll_angle, "deg");
    j["roll_sd"] = quantityJson(g.roll_sd, "deg");
    j["stem_segments"] = g.stem_segments;
    j["stem_angle"] = quantityJson(g.stem_angle, "deg");
    j["avoid_collisions"] = g.avoid_collisions;
    j["wall_clearance"] = quantityJson(g.wall_clearance, "mm");
    j["tries"] = g.tries;
    j["min_tip_fraction"] = g.min_tip_fraction;
    j["murray_exponent"] = physics_summary.murray_exponent;
    describeInflow(physics_summary, j);
    return j;
  }
  j["mode"] = "lzh";
  j["dimension"] = p.dimension;
  j["voxel_size"] = quantityJson(voxel_mm, "mm");
  j["block_width"] = quantityJson(p.block_width, "mm");
  j["block_height"] = quantityJson(p.height, "mm");
  j["start_length"] = quantityJson(p.start_length, "mm");
  j["capillary_length"] = quantityJson(p.capillary_length, "mm");
  j["start_diameter"] = quantityJson(p.start_diameter, "mm");
  j["capillary_diameter"] = quantityJson(p.capillary_diameter, "mm");
  j["start_wall"] = quantityJson(p.start_wall, "mm");
  j["capillary_wall"] = quantityJson(p.capillary_wall, "mm");
  j["capillary_spacing"] = quantityJson(p.spacing, "mm");
  j["level_rule"] = p.printed_level_rule ? "printed: N = ceil(log2(c/d))" : "corrected: N = ceil(log2(c/d + 1))";
  describeInflow(physics_summary, j);
  j["outlet_pressure"] = quantityJson(physics_summary.terminal_pressure, "Pa");
  return j;
}

std::unique_ptr<PreparedGrowth> LsystemSetup::prepare(std::uint64_t memory_limit) const {
  if (grammar) return std::make_unique<PreparedGrammar>(*this, loadDomainSpec(domain, parameter_file, root, memory_limit));
  return std::make_unique<PreparedLsystem>(*this);
}

const GrowthMethod kLsystemMethod{
    "lsystem",
    "L-system vessel networks. Mode lzh (Lázaro 2011): a printable closed network from high-level parameters "
    "(block, start and capillary vessels, capillary spacing) inverted into levels N, angle θ and lengths L_n; a 3D turtle "
    "with a 90° roll per level; the venous half mirrored through the block's mid-plane and joined by vertical capillaries; "
    "diameter and wall thickness linear in path length (tapered vessels). Mode grammar (Galarreta-Valverde 2013, as V-System): "
    "the stochastic grammar F(d) → {S(d)} [+θ1 /β F(d1)] [−θ2 /β F(d2)] with curved stems, Murray or ratio diameters and "
    "Zamir or fixed angles, grown breadth first inside a domain without overlaps",
    {
        {"domain", "voxel_size", "mm", nullptr, "the voxel edge (lzh: the frame is the block with room for the vessels; grammar: of the domain's frame)"},
        {"domain", "shape", "text", "sphere", "grammar: sphere, cube, disc or square (2D), or mask"},
        {"domain", "radius", "mm", nullptr, "grammar: sphere and disc: the radius"},
        {"domain", "side", "mm", nullptr, "grammar: cube and square: the side"},
        {"domain", "mask", "file", nullptr, "grammar, shape = \"mask\": a NIfTI volume (voxels > 0 inside) or a VascuSynth box map"},
        {"tree", "mode", "text", "lzh", "lzh: Lázaro's inverse problem; grammar: the stochastic vessel grammar (V-System)"},
        {"tree", "root_offset", "[x, y(, z)] mm", "the top (+y)", "grammar, analytic shapes: the root relative to the centre"},
        {"tree", "root", "[x, y, z] mm", nullptr, "grammar, masks: the root in mm in the frame (or root_voxel)"},
        {"tree", "root_voxel", "[x, y, z] mask voxels", nullptr, "grammar, masks: the root in voxels (or root)"},
        {"tree", "direction", "[x, y(, z)]", "toward the domain's centre", "grammar: the first stem's heading"},
        {"tree", "iterations", "count", "6", "grammar: n, bifurcation generations (2^n tips)"},
        {"tree", "root_diameter", "mm", "[domain] diameter × 0.02", "grammar: d0, the first stem's diameter"},
        {"tree", "length_ratio", "", "10", "grammar: ε, a stem is ε·d long"},
        {"tree", "length_margin", "", "0.2", "grammar: m, the stem length is drawn uniformly in ε·d·[1 − m, 1 + m]"},
        {"tree", "diameter_sd", "", "0.2", "grammar: the first daughter's diameter is normal around d/2^(1/k), this standard deviation relative to it (0: exact)"},
        {"tree", "radii", "text", "murray", "grammar: murray (the second daughter by Murray's law with [physics] murray_exponent) or ratio (both d·radius_ratio)"},
        {"tree", "radius_ratio", "", "0.7937", "grammar, radii = \"ratio\": daughter over parent diameter"},
        {"tree", "angles", "text", "zamir", "grammar: zamir (the optimal angles of the daughters' diameters, as V-System) or fixed (±branch_angle)"},
        {"tree", "branch_angle", "deg", "35", "grammar, angles = \"fixed\": each daughter's angle to its parent"},
        {"tree", "angle_sd", "deg", "0", "grammar: normal spread added to each daughter's angle"},
        {"tree", "roll_angle", "deg", "70", "grammar: β, the roll of each daughter's frame (3D: successive bifurcation planes differ)"},
        {"tree", "roll_sd", "deg", "0", "grammar: normal spread of β"},
        {"tree", "stem_segments", "count", "5", "grammar: pieces of a stem"},
        {"tree", "stem_angle", "deg", "25", "grammar: the turns between a stem's pieces (+ − − +, or mirrored)"},
        {"tree", "avoid_collisions", "true/false", "true", "grammar: a stem that would overlap a vessel is drawn again"},
        {"tree", "wall_clearance", "mm", "0 mm", "grammar: vessels keep this much beyond their radius from the domain's wall"},
        {"tree", "tries", "count", "8", "grammar: draws of a stem (later ones in another plane about the parent) before its branch is dropped"},
        {"tree", "min_tip_fraction", "", "0.9", "grammar: the run fails when fewer than this fraction of the 2^n tips grow"},
        {"tree", "dimension", "count", "3", "2: one plane (2^N capillaries in a row); 3: levels alternate between two planes (a 2^N × 2^N capillary grid)"},
        {"tree", "block_width", "mm", nullptr, "w_b, the block's width (3D: w_b × w_b × h)"},
        {"tree", "block_height", "mm", nullptr, "h, from the inlet's top to the outlet's bottom"},
        {"tree", "start_length", "mm", nullptr, "L_s, the vertical inlet (and outlet) vessel"},
        {"tree", "capillary_length", "mm", nullptr, "L_c, the vertical capillaries"},
        {"tree", "start_diameter", "mm", nullptr, "d_s, the lumen at the inlet"},
        {"tree", "capillary_diameter", "mm", nullptr, "d_c, the lumen of the capillaries"},
        {"tree", "start_wall", "mm", "0 mm", "t_ws, the wall thickness at the inlet"},
        {"tree", "capillary_wall", "mm", "0 mm", "t_wc, the wall thickness of the capillaries"},
        {"tree", "capillary_spacing", "mm", nullptr, "d, the largest distance between neighbouring capillaries (and twice their distance from the block's sides)"},
        {"tree", "level_rule", "text", "corrected", "corrected: N = ⌈log2(c/d + 1)⌉, so capillaries lie at most d apart; printed: the thesis's ⌈log2(c/d)⌉ (farther apart than d when c/d is a power of 2)"},
        {"physics", "murray_exponent", "", "3", "grammar: k of Murray's law d^k = d1^k + d2^k"},
        {"physics", "viscosity", "Pa*s", "0.0036 Pa*s", "blood viscosity η (flows and pressures of the outputs)"},
        {"physics", "perfusion_pressure", "Pa", "100 mmHg", "pressure at the inlet (grammar: the root)"},
        {"physics", "perfusion_flow", "mm^3/s", "1 mL/min", "Q into the inlet: lzh, the same through every capillary, the outlet's pressure follows (Poiseuille, tapered vessels); grammar, split equally among the tips"},
    },
    &readLsystemToml};

}  // namespace angiosynth
