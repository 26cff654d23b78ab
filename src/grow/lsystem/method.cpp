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

constexpr const char* kRadiiWords[] = {"ratio", "murray", nullptr};           // GrammarOptions::murray false, true
constexpr const char* kAnglesWords[] = {"fixed", "zamir", nullptr};           // GrammarOptions::zamir_angles false, true
constexpr const char* kLevelRuleWords[] = {"corrected", "printed", nullptr};  // LzhParameters::printed_level_rule false, true

// Mode grammar's [tree] settings.
// clang-format off
const std::vector<Setting<GrammarOptions>>& grammarSettings() {
  using O = GrammarOptions;
  static const std::vector<Setting<O>> settings{
      {.table = "tree", .key = "iterations", .unit = "count", .fallback = "6", .meaning = "grammar: n, bifurcation generations (2^n tips)",
       .field = &O::iterations, .range = {0, 20}, .fallback_is_value = true},
      {.table = "tree", .key = "root_diameter", .unit = "mm", .fallback = "[domain] diameter × 0.02", .meaning = "grammar: d0, the first stem's diameter",
       .field = &O::root_diameter, .range = {2 * Limits::kMinRadius, 2 * Limits::kMaxRadius}, .quantity = Dimension::Length},
      {.table = "tree", .key = "length_ratio", .unit = "", .fallback = "10", .meaning = "grammar: ε, a stem is ε·d long",
       .field = &O::length_ratio, .range = {0, 1e4, true, false}, .fallback_is_value = true},
      {.table = "tree", .key = "length_margin", .unit = "", .fallback = "0.2", .meaning = "grammar: m, the stem length is drawn uniformly in ε·d·[1 − m, 1 + m]",
       .field = &O::length_margin, .range = {0, 1, false, true}, .fallback_is_value = true},
      {.table = "tree", .key = "diameter_sd", .unit = "", .fallback = "0.2",
       .meaning = "grammar: the first daughter's diameter is normal around d/2^(1/k), this standard deviation relative to it (0: exact)",
       .field = &O::diameter_sd, .range = {0, 10}, .fallback_is_value = true},
      {.table = "tree", .key = "radii", .unit = "text", .fallback = "murray",
       .meaning = "grammar: murray (the second daughter by Murray's law with [physics] murray_exponent) or ratio (both d·radius_ratio)",
       .field = enumChoice<O, &O::murray, kRadiiWords>(), .choices = wordList(kRadiiWords), .fallback_is_value = true},
      {.table = "tree", .key = "radius_ratio", .unit = "", .fallback = "0.7937", .meaning = "grammar, radii = \"ratio\": daughter over parent diameter",
       .field = &O::radius_ratio, .range = {0, 1, true, true}, .only_with = {"radii", "ratio"}, .fallback_is_value = true},
      {.table = "tree", .key = "angles", .unit = "text", .fallback = "zamir",
       .meaning = "grammar: zamir (the optimal angles of the daughters' diameters, as V-System) or fixed (±branch_angle)",
       .field = enumChoice<O, &O::zamir_angles, kAnglesWords>(), .choices = wordList(kAnglesWords), .fallback_is_value = true},
      {.table = "tree", .key = "branch_angle", .unit = "deg", .fallback = "35", .meaning = "grammar, angles = \"fixed\": each daughter's angle to its parent",
       .field = &O::branch_angle, .range = {0, 90}, .only_with = {"angles", "fixed"}, .fallback_is_value = true},
      {.table = "tree", .key = "angle_sd", .unit = "deg", .fallback = "0", .meaning = "grammar: normal spread added to each daughter's angle",
       .field = &O::angle_sd, .range = {0, 90}, .fallback_is_value = true},
      {.table = "tree", .key = "roll_angle", .unit = "deg", .fallback = "70",
       .meaning = "grammar: β, the roll of each daughter's frame (3D: successive bifurcation planes differ)",
       .field = &O::roll_angle, .range = {-360, 360}, .fallback_is_value = true},
      {.table = "tree", .key = "roll_sd", .unit = "deg", .fallback = "0", .meaning = "grammar: normal spread of β",
       .field = &O::roll_sd, .range = {0, 360}, .fallback_is_value = true},
      {.table = "tree", .key = "stem_segments", .unit = "count", .fallback = "5", .meaning = "grammar: pieces of a stem",
       .field = &O::stem_segments, .range = {1, 100}, .fallback_is_value = true},
      {.table = "tree", .key = "stem_angle", .unit = "deg", .fallback = "25", .meaning = "grammar: the turns between a stem's pieces (+ − − +, or mirrored)",
       .field = &O::stem_angle, .range = {0, 90, false, true}, .fallback_is_value = true},
      {.table = "tree", .key = "avoid_collisions", .unit = "true/false", .fallback = "true",
       .meaning = "grammar: a stem that would overlap a vessel is drawn again", .field = &O::avoid_collisions},
      {.table = "tree", .key = "wall_clearance", .unit = "mm", .fallback = "0 mm",
       .meaning = "grammar: vessels keep this much beyond their radius from the domain's wall",
       .field = &O::wall_clearance, .range = {0, Limits::kMaxLength}, .quantity = Dimension::Length, .fallback_is_value = true},
      {.table = "tree", .key = "tries", .unit = "count", .fallback = "8",
       .meaning = "grammar: draws of a stem (later ones in another plane about the parent) before its branch is dropped",
       .field = &O::tries, .range = {1, 1000}, .fallback_is_value = true},
      {.table = "tree", .key = "min_tip_fraction", .unit = "", .fallback = "0.9", .meaning = "grammar: the run fails when fewer than this fraction of the 2^n tips grow",
       .field = &O::min_tip_fraction, .range = {0, 1}, .fallback_is_value = true},
  };
  return settings;
}
// clang-format on

// Mode lzh's [tree] settings (Lázaro 2011's high-level parameters).
// clang-format off
const std::vector<Setting<LzhParameters>>& lzhSettings() {
  using O = LzhParameters;
  const auto length = [](const char* key, const char* meaning, double O::*field) {
    return Setting<O>{.table = "tree", .key = key, .unit = "mm", .fallback = nullptr, .meaning = meaning, .field = field,
                      .range = {0, Limits::kMaxLength, true, false}, .quantity = Dimension::Length};
  };
  const auto wall = [](const char* key, const char* meaning, double O::*field) {
    return Setting<O>{.table = "tree", .key = key, .unit = "mm", .fallback = "0 mm", .meaning = meaning, .field = field,
                      .range = {0, Limits::kMaxLength}, .quantity = Dimension::Length, .fallback_is_value = true};
  };
  static const std::vector<Setting<O>> settings{
      {.table = "tree", .key = "dimension", .unit = "count", .fallback = "3",
       .meaning = "2: one plane (2^N capillaries in a row); 3: levels alternate between two planes (a 2^N × 2^N capillary grid)",
       .field = &O::dimension, .range = {2, 3}, .fallback_is_value = true},
      length("block_width", "w_b, the block's width (3D: w_b × w_b × h)", &O::block_width),
      length("block_height", "h, from the inlet's top to the outlet's bottom", &O::height),
      length("start_length", "L_s, the vertical inlet (and outlet) vessel", &O::start_length),
      length("capillary_length", "L_c, the vertical capillaries", &O::capillary_length),
      length("start_diameter", "d_s, the lumen at the inlet", &O::start_diameter),
      length("capillary_diameter", "d_c, the lumen of the capillaries", &O::capillary_diameter),
      wall("start_wall", "t_ws, the wall thickness at the inlet", &O::start_wall),
      wall("capillary_wall", "t_wc, the wall thickness of the capillaries", &O::capillary_wall),
      length("capillary_spacing", "d, the largest distance between neighbouring capillaries (and twice their distance from the block's sides)", &O::spacing),
      {.table = "tree", .key = "level_rule", .unit = "text", .fallback = "corrected",
       .meaning = "corrected: N = ⌈log2(c/d + 1)⌉, so capillaries lie at most d apart; printed: the thesis's ⌈log2(c/d)⌉ (farther apart than d "
                  "when c/d is a power of 2)",
       .field = enumChoice<O, &O::printed_level_rule, kLevelRuleWords>(), .choices = wordList(kLevelRuleWords), .fallback_is_value = true},
  };
  return settings;
}
// clang-format on

// clang-format off
const std::vector<Setting<PhysicsParameters>>& lsystemPhysics() {
  static const std::vector<Setting<PhysicsParameters>> settings = [] {
    auto murray = physicsSetting("murray_exponent", "3");
    murray.meaning = "grammar: k of Murray's law d^k = d1^k + d2^k";
    auto band_edges = physicsSetting("murray_band_edges", "none");
    band_edges.meaning = "grammar: parent radii splitting the bifurcations into bands with a k each (murray_band_exponents, which then "
                         "replace murray_exponent): ascending, each at least 1.25 times the one before";
    auto band_exponents = physicsSetting("murray_band_exponents", "none");
    auto viscosity = physicsSetting("viscosity", "0.0036 Pa*s");
    viscosity.meaning = "blood viscosity η (flows and pressures of the outputs)";
    auto pressure = physicsSetting("perfusion_pressure", "100 mmHg");
    pressure.meaning = "pressure at the inlet (grammar: the root)";
    auto flow = physicsSetting("perfusion_flow", "1 mL/min");
    flow.meaning = "Q into the inlet: lzh, the same through every capillary, the outlet's pressure follows (Poiseuille, tapered vessels); "
                   "grammar, split equally among the tips";
    return std::vector<Setting<PhysicsParameters>>{murray, band_edges, band_exponents, viscosity, pressure, flow};
  }();
  return settings;
}
// clang-format on

// The keys only mode grammar reads (its domain, root and settings, and Murray's exponent): such
// a key in an lzh file, or a key of lzh's settings in a grammar file, is an error naming its mode.
bool grammarOnly(const std::string& table, const std::string& key) {
  static const std::set<std::string> domain{"shape", "radius", "side", "mask"}, tree{"root_offset", "root", "root_voxel", "direction"};
  if (table == "domain") return domain.count(key) > 0;
  if (table == "physics") return key == "murray_exponent" || key == "murray_band_edges" || key == "murray_band_exponents";
  return tree.count(key) > 0 || settingKeys(grammarSettings()).count(key) > 0;
}

void forbidOtherModeKeys(const TomlReader& r, const GrowthMethod& m, bool grammar,
                         const std::vector<std::pair<const char*, const toml::table*>>& tables) {
  for (const auto& [name, t] : tables)
    for (const auto& p : m.params) {
      if (std::string(p.table) != name || !t->get(p.key)) continue;
      const bool grammar_key = grammarOnly(name, p.key);
      const bool shared = std::string(p.key) == "mode" || std::string(p.key) == "voxel_size" || std::string(name) == "physics";
      if (shared && !grammar_key) continue;
      if (grammar_key != grammar)
        throw InputError(r.file(), r.lineOf(t->get(p.key)),
                         "'" + std::string(p.key) + "' in [" + name + "] is for mode " + (grammar_key ? "grammar" : "lzh") +
                             "; this file's mode is " + (grammar ? "grammar" : "lzh") + " ([tree] mode)");
    }
}

void readGrammar(const TomlReader& r, const toml::table& dom, const toml::table& tree, LsystemSetup& s) {
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
  readSettingsFrom(r, tree, "tree", grammarSettings(), g, s.voxel_mm);
  g.murray_exponent = s.physics_summary.murray_exponent;
  g.murray_band_edges = s.physics_summary.murray_band_edges;
  g.murray_band_exponents = s.physics_summary.murray_band_exponents;
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
    if (!options_.root_diameter) options_.root_diameter = s.root_diameter_fraction * diameterOf(loaded_);
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
    } catch (const GrowthError& e) { throw InputError(setup_.parameter_file, setup_.tree_line, e.what()); }
    flowsAndPressures(t, setup_.physics_summary, gr_.tips > 0 ? setup_.physics_summary.perfusion_flow / double(gr_.tips) : 0.0);
    const auto t0 = std::chrono::steady_clock::now();
    report.intersecting_pairs = std::int64_t(crossingPairs(t).size());
    check_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    report.root_radius_mm = *o.root_diameter / 2;
    return singleTreeForest(std::move(t));
  }
  void addStatistics(const GrowthReport&, Json& stats) const override {
    stats["root_diameter"] = quantityJson(*options_.root_diameter, "mm");
    stats["tips_asked"] = gr_.asked_tips;
    stats["tips"] = gr_.tips;
    stats["stems_redrawn"] = gr_.redrawn;
    stats["branches_dropped_outside"] = gr_.dropped_outside;
    stats["branches_dropped_collision"] = gr_.dropped_collision;
    stats["timing_seconds"] = Json{{"crossing_check", check_seconds_}};  // a time: not sample data
    stats["intersecting_pairs_note"] =
        "lsystem: segments whose capsules overlap, unless the path between them along the tree is shorter than their radii";
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
  s->physics_summary = readPhysics(r, lsystemPhysics(), ph);
  if (s->grammar) {
    readGrammar(r, dom, tree, *s);
    return s;
  }
  s->voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
  checkRange(s->voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(dom, "voxel_size"), "voxel_size (mm)");
  auto& p = s->lzh;
  readSettingsFrom(r, tree, "tree", lzhSettings(), p, s->voxel_mm);
  auto& phys = s->physics_summary;
  p.viscosity = phys.viscosity;
  p.perfusion_pressure = phys.perfusion_pressure;
  p.perfusion_flow = phys.perfusion_flow;
  try {
    s->plan = planLzh(p);
  } catch (const LzhError& e) { throw InputError(r.file(), tree.get(e.key) ? r.lineOf(tree.get(e.key)) : r.lineOf(&tree), e.what()); }
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
    j.update(settingsJson(grammarSettings(), g));
    j.update(settingsJson(lsystemPhysics(), physics_summary));
    return j;
  }
  j["mode"] = "lzh";
  j["voxel_size"] = quantityJson(voxel_mm, "mm");
  j.update(settingsJson(lzhSettings(), p));
  auto inflow = settingsJson(lsystemPhysics(), physics_summary);
  for (const char* key : {"murray_exponent", "murray_band_edges", "murray_band_exponents"}) inflow.erase(key);  // grammar only
  j.update(inflow);
  j["outlet_pressure"] = quantityJson(physics_summary.terminal_pressure, "Pa");
  return j;
}

std::unique_ptr<PreparedGrowth> LsystemSetup::prepare(std::uint64_t memory_limit) const {
  if (grammar) return std::make_unique<PreparedGrammar>(*this, loadDomainSpec(domain, parameter_file, root, memory_limit));
  return std::make_unique<PreparedLsystem>(*this);
}

// clang-format off
const GrowthMethod kLsystemMethod{
    "lsystem",
    "L-system vessel networks. Mode lzh (Lázaro 2011): a printable closed network from high-level parameters "
    "(block, start and capillary vessels, capillary spacing) inverted into levels N, angle θ and lengths L_n; a 3D turtle "
    "with a 90° roll per level; the venous half mirrored through the block's mid-plane and joined by vertical capillaries; "
    "diameter and wall thickness linear in path length (tapered vessels). Mode grammar (Galarreta-Valverde 2013, as V-System): "
    "the stochastic grammar F(d) → {S(d)} [+θ1 /β F(d1)] [−θ2 /β F(d2)] with curved stems, Murray or ratio diameters and "
    "Zamir or fixed angles, grown breadth first inside a domain without overlaps",
    joinRows({{
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
    }, settingRows(grammarSettings()), settingRows(lzhSettings()), settingRows(lsystemPhysics())}),
    &readLsystemToml};
// clang-format on

}  // namespace angiosynth
