// Method "colonisation": its parameters, TOML reader, description, domains and grow function.
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "core/point_hash.hpp"
#include "grow/colonisation/setup.hpp"
#include "grow/common/chain_trees.hpp"
#include "grow/common/intersections.hpp"
#include "grow/common/method_tables.hpp"
#include "grow/common/region_tables.hpp"
#include "io/growth_domain_files.hpp"
#include "io/network_files.hpp"
#include "settings/param_checks.hpp"
#include "settings/input_paths.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

constexpr const char* kSpreadWords[] = {"sd", "rms", nullptr};
constexpr const char* kSourceWords[] = {"volume", "surface", nullptr};

// clang-format off
const std::vector<Setting<ColonisationOptions>>& colonisationSettings() {
  using O = ColonisationOptions;
  static const std::vector<Setting<O>> settings{
      {.table = "tree", .key = "veins", .unit = "true/false", .fallback = "true", .meaning = "grow the venous system (needs a vein root)",
       .field = &O::veins},
      {.table = "tree", .key = "sigma0", .unit = "", .fallback = "1", .meaning = "σ_0, the tissue's initial size (σ_t = σ_0 + Σ Δσ)",
       .field = &O::sigma0, .range = {0, 1e6, true, false}, .fallback_is_value = true},
      {.table = "tree", .key = "avoid_crossing", .unit = "true/false", .fallback = "false",
       .meaning = "no new vessel comes closer to another than their radii", .field = &O::avoid_crossing},
  };
  return settings;
}
// clang-format on

// A [[stage]]'s settings but its lengths.
// clang-format off
const std::vector<Setting<ColonisationStage>>& stageSettings() {
  using O = ColonisationStage;
  static const std::vector<Setting<O>> settings{
      {.table = "stage", .key = "name", .unit = "text", .fallback = "stage_1, stage_2, ...", .meaning = "the stage's name in sample.json",
       .field = &O::name},
      {.table = "stage", .key = "steps", .unit = "count", .fallback = "100", .meaning = "iterations of the stage",
       .field = &O::steps, .range = {1, 100000}, .fallback_is_value = true},
      {.table = "stage", .key = "drains_per_step", .unit = "count", .fallback = "1000", .meaning = "oxygen drains sampled per step",
       .field = &O::drains_per_step, .range = {1, 10000000}, .fallback_is_value = true},
      {.table = "stage", .key = "drain_lifetime", .unit = "count", .fallback = "1",
       .meaning = "steps an unsatisfied drain (or CO2 source) lives (0: until satisfied); satisfied drains go at once",
       .field = &O::drain_lifetime, .range = {0, 1000000}, .fallback_is_value = true},
      {.table = "stage", .key = "delta_sigma", .unit = "", .fallback = "0.02", .meaning = "Δσ, tissue growth per step",
       .field = &O::delta_sigma, .range = {0, 100}, .fallback_is_value = true},
      {.table = "stage", .key = "perception_angle", .unit = "deg", .fallback = "90", .meaning = "γ, the full angle of the perception cone",
       .field = &O::perception_angle, .range = {0, 360, true, false}, .fallback_is_value = true},
      {.table = "stage", .key = "bias", .unit = "", .fallback = "0.5",
       .meaning = "ω in [0, 1]: weight of the current (or Murray-branch) direction against the drains' mean",
       .field = &O::bias, .range = {0, 1}, .fallback_is_value = true},
      {.table = "stage", .key = "bifurcation_spread", .unit = "deg", .fallback = "10", .meaning = "φ: a leaf splits when its drains' angular spread exceeds it",
       .field = &O::bifurcation_spread, .range = {0, 180}, .fallback_is_value = true},
      {.table = "stage", .key = "spread_statistic", .unit = "text", .fallback = "sd",
       .meaning = "sd (the standard deviation of the angles to their mean direction, as the paper) or rms (their root mean square)",
       .field = enumChoice<O, &O::spread, kSpreadWords>(), .choices = wordList(kSpreadWords), .fallback_is_value = true},
      {.table = "stage", .key = "lateral", .unit = "true/false", .fallback = "true", .meaning = "inter-nodes may take lateral branches",
       .field = &O::lateral},
      {.table = "stage", .key = "source", .unit = "text", .fallback = "volume",
       .meaning = "volume: drains anywhere in the stage's region; surface: within surface_depth of the border",
       .field = enumChoice<O, &O::source, kSourceWords>(), .choices = wordList(kSourceWords), .fallback_is_value = true},
  };
  return settings;
}
// clang-format on

// A [[stage]]'s lengths: given in mm, or a share of the domain's diameter (the fallback's "× f").
// clang-format off
const std::vector<Setting<ColonisationStageSpec>>& stageLengthSettings() {
  using O = ColonisationStageSpec;
  const auto length = [](const char* key, const char* fallback, const char* meaning, std::optional<double> O::*field) {
    return Setting<O>{.table = "stage", .key = key, .unit = "mm", .fallback = fallback, .meaning = meaning, .field = field,
                      .range = {0, Limits::kMaxLength}, .quantity = Dimension::Length};
  };
  static const std::vector<Setting<O>> settings{
      length("step", "[domain] diameter × 0.008", "d, the growth step (at the last step; × σ_T/σ_t at step t)", &O::step),
      length("perception_distance", "[domain] diameter × 0.04", "δ, how far a node perceives drains", &O::perception_distance),
      length("satisfaction_distance", "[domain] diameter × 0.01", "a drain this close to a node of its system is supplied", &O::satisfaction_distance),
      length("co2_distance", "[domain] diameter × 0.04",
             "tissue this close to an artery makes CO2: a drain for the veins (unless a vein is within satisfaction_distance)", &O::co2_distance),
      length("drain_spacing", "[domain] diameter × 0.005", "minimum distance between drains", &O::drain_spacing),
      length("terminal_radius", "[domain] diameter × 0.0004", "r, the radius of every leaf", &O::terminal_radius),
      length("surface_depth", "[domain] diameter × 0.01", "source = surface: the shell drains and new nodes lie in", &O::surface_depth),
  };
  return settings;
}
// clang-format on

// A stage length in mm: as given, or its declared share of the domain's diameter.
double stageLength(const ColonisationStageSpec& spec, std::optional<double> ColonisationStageSpec::*field, double diameter) {
  if (spec.*field) return *(spec.*field);
  for (const auto& s : stageLengthSettings())
    if (std::get<std::optional<double> ColonisationStageSpec::*>(s.field) == field) {
      const std::string fallback = s.fallback;
      return std::stod(fallback.substr(fallback.find("× ") + 3)) * diameter;
    }
  throw std::logic_error("an undeclared stage length");
}

// clang-format off
const std::vector<Setting<PhysicsParameters>>& colonisationPhysics() {
  static const std::vector<Setting<PhysicsParameters>> settings = [] {
    auto murray = physicsSetting("murray_exponent", "2.55");
    murray.meaning = "κ in (2, 4): r_p^κ = r_a^κ + r_b^κ";
    murray.range = {2, 4, true, true};
    auto band_edges = physicsSetting("murray_band_edges", "none");
    auto band_exponents = physicsSetting("murray_band_exponents", "none");
    band_exponents.meaning = "κ of each band of parent radius, in (2, 4), the smallest radii first: one more than murray_band_edges, at most 8";
    band_exponents.range = murray.range;
    auto viscosity = physicsSetting("viscosity", "0.0036 Pa*s");
    viscosity.meaning = "blood viscosity η (flows and pressures of the outputs)";
    auto pressure = physicsSetting("perfusion_pressure", "100 mmHg");
    pressure.meaning = "pressure at the arterial roots";
    auto venous = physicsSetting("terminal_pressure", "5 mmHg");
    venous.key = "venous_pressure";
    venous.meaning = "pressure at the venous roots";
    auto flow = physicsSetting("perfusion_flow", "1 mL/min");
    flow.meaning = "Q, split equally among the leaves of each system";
    return std::vector<Setting<PhysicsParameters>>{murray, band_edges, band_exponents, viscosity, pressure, venous, flow};
  }();
  return settings;
}
// clang-format on

class PreparedColonisation final : public PreparedGrowth {
 public:
  PreparedColonisation(const ColonisationSetup& s, GrowthDomain loaded) : setup_(s), loaded_(std::move(loaded)) {
    const auto list = [&](const std::vector<std::string>& names) { return regionsNamed(s.regions, names); };
    const auto fail = [&](int line, const GrowthError& e) { return InputError(s.parameter_file, line, e.what()); };
    try {  // the world: the domain without its avascular regions
      if (!s.avascular.empty())
        world_ = std::make_unique<GrowthDomain>(regionDomain(loaded_, {}, list(s.avascular), "the domain without its avascular regions"));
    } catch (const GrowthError& e) { throw fail(0, e); }
    const GrowthDomain& world = *(world_ ? world_.get() : &loaded_);
    options_ = s.options;
    options_.world = &world;
    const double diameter = diameterOf(loaded_);
    for (const auto& spec : s.stages) {
      auto st = spec.stage;
      using Spec = ColonisationStageSpec;
      st.step = stageLength(spec, &Spec::step, diameter);
      st.perception_distance = stageLength(spec, &Spec::perception_distance, diameter);
      st.satisfaction_distance = stageLength(spec, &Spec::satisfaction_distance, diameter);
      st.co2_distance = stageLength(spec, &Spec::co2_distance, diameter);
      st.drain_spacing = stageLength(spec, &Spec::drain_spacing, diameter);
      st.terminal_radius = stageLength(spec, &Spec::terminal_radius, diameter);
      st.surface_depth = stageLength(spec, &Spec::surface_depth, diameter);
      if (spec.domain.empty()) {
        st.drains = &world;
      } else {
        try {
          drains_.push_back(
              std::make_unique<GrowthDomain>(regionDomain(world, list(spec.domain), {}, "the drain region of stage '" + st.name + "'")));
        } catch (const GrowthError& e) { throw fail(spec.line, e); }
        st.drains = drains_.back().get();
      }
      // Lengths the domain can hold: a step beyond half its diameter leaves it at once, a step
      // of 0 never moves; a leaf a hundredth of the domain across already makes a root of a
      // fifth of it at a few thousand leaves (Murray's law).
      const auto where = [&](const char* key) { return spec.lines.count(key) ? spec.lines.at(key) : spec.line; };
      if (!(st.step >= physical::kMinStepMm && st.step <= diameter / 2))
        throw InputError(s.parameter_file, where("step"),
                         "stage '" + st.name + "': step " + show(st.step) + " mm is out of range; allowed: " + show(physical::kMinStepMm) +
                             " mm to half the domain's diameter (" + show(diameter / 2) + " mm)");
      if (!(st.terminal_radius >= physical::kMinRadiusMm && st.terminal_radius <= diameter / 100))
        throw InputError(s.parameter_file, where("terminal_radius"),
                         "stage '" + st.name + "': terminal_radius " + show(st.terminal_radius) + " mm is out of range; allowed: " +
                             show(physical::kMinRadiusMm) + " mm to a hundredth of the domain's diameter (" + show(diameter / 100) + " mm)");
      if (!(st.perception_distance > st.satisfaction_distance))
        throw InputError(s.parameter_file, spec.line,
                         "stage '" + st.name + "': perception_distance (" + show(st.perception_distance) +
                             " mm) must exceed satisfaction_distance (" + show(st.satisfaction_distance) +
                             " mm), or no drain is ever perceived before it is satisfied");
      options_.stages.push_back(st);
    }
    // Roots: placed in the domain, heading to its centre unless given a direction.
    for (const auto& r : s.roots) {
      ColonisationRoot root;
      if (r.beside_artery) {
        // Beside the artery's root, as vessels enter an organ together: 0.05 D along x, then
        // toward the centre until inside.
        const Vec3 a = options_.roots.front().position, c = world.center();
        Vec3 p = a + Vec3(0.05 * diameter, 0, 0);
        for (int it = 0; it < 1000 && world.depth(p) < 0; ++it) p = p + (c - p) * 0.01;
        if (world.depth(p) < 0)
          throw InputError(s.parameter_file, r.line,
                           "no default vein root beside the artery's fits the domain; give the roots as [[tree.inlet]] tables");
        root.position = p;
      } else {
        root.position = placeRoot(s.parameter_file, r.root, world);
      }
      root.vein = r.kind == "vein";
      Vec3 d = r.has_direction ? r.direction : world.center() - root.position;
      if (!r.has_direction && options_.stages.front().source == DrainSource::Surface) {
        // Surface growth: along the border, not into the domain.
        const Vec3 n = d / norm(d);
        d = cross(n, std::abs(n.z) < 0.9 ? Vec3(0, 0, 1) : Vec3(1, 0, 0));
      }
      if (world.dimension() == 2) d.z = 0;
      if (!(norm(d) > 0)) d = Vec3(0, -1, 0);
      root.direction = d / norm(d);
      options_.roots.push_back(root);
      ids_.push_back(r.id);
      kinds_.push_back(r.kind);
    }
    // [initial]: each root of the network is a stump of its own tree.
    if (!s.initial_file.empty()) {
      const auto& net = s.initial.tree;
      int nth = 0;
      for (auto root : net.roots()) {
        VascularTree t;
        std::vector<std::int32_t> id(std::size_t(net.nodeCount()), -1), queue{root};
        for (std::size_t q = 0; q < queue.size(); ++q) {
          const auto i = queue[q];
          Vec3 p = net.position[i] + (s.initial_from_corner ? Vec3() : world.center());
          if (world.dimension() == 2) p.z = world.planeZ();
          id[std::size_t(i)] = t.addNode(p, net.isRoot(i) ? -1 : id[std::size_t(net.parent[i])]);
          t.radius[id[std::size_t(i)]] = net.radius[i];
          if (!(world.depth(p) > -1e-9 * diameter))
            throw InputError(s.initial_file.string(), s.initial.lines[std::size_t(i)],
                             "node " + s.initial.ids[std::size_t(i)] + " lies outside the domain (" + show(-world.depth(p)) +
                                 " mm beyond its border); space colonisation keeps every node inside");
          for (auto c : {net.child0[i], net.child1[i]})
            if (c >= 0) queue.push_back(c);
        }
        if (net.child1[root] >= 0)
          throw InputError(s.initial_file.string(), s.initial.lines[std::size_t(root)],
                           "a root of the network starts two vessels; a tree's root has one");
        stumps_.push_back(std::make_unique<VascularTree>(std::move(t)));
        ColonisationRoot r;
        r.position = stumps_.back()->position[0];
        r.vein = s.initial_kind == "vein";
        r.direction = Vec3(0, -1, 0);
        r.stump = stumps_.back().get();
        options_.roots.push_back(r);
        ids_.push_back(s.initial_kind + "_initial_" + std::to_string(++nth));
        kinds_.push_back(s.initial_kind);
      }
    }
  }
  const DemandMap& frame() const override { return loaded_.frame(); }
  void checkFeasibility() const override {}
  const GrowthDomain* domain() const override { return options_.world; }
  Forest grow(std::uint64_t seed, std::uint64_t sample, GrowthReport& report, const ProgressFn& progress) const override {
    auto o = options_;
    o.seed = seed;
    o.sample = sample;
    cr_ = ColonisationReport{};
    auto trees = growColonisation(o, report, cr_, progress);
    if (o.avoid_crossing) cr_.pruned = pruneCrossings(trees, colonisationLaw(o));
    Forest f;
    for (std::size_t k = 0; k < trees.size(); ++k) {
      // Each system's leaves share Q equally: an artery supplies what a vein drains.
      std::int64_t same = 0;
      for (std::size_t q = 0; q < trees.size(); ++q)
        if (o.roots[q].vein == o.roots[k].vein)
          for (std::int32_t i = 0; i < trees[q].nodeCount(); ++i) same += !trees[q].isRoot(i) && trees[q].child0[i] < 0;
      auto p = setup_.physics_summary;
      if (o.roots[k].vein) std::swap(p.perfusion_pressure, p.terminal_pressure);
      flowsAndPressures(trees[k], p, same > 0 ? p.perfusion_flow / double(same) : 0.0);
      f.vessels.appendTree(trees[k], int(k));
      f.trees.push_back(TreeInfo{ids_[k], kinds_[k], 0});
    }
    assignClassLabels(f.trees);
    const auto t0 = std::chrono::steady_clock::now();
    report.intersecting_pairs = std::int64_t(crossingPairs(f.vessels).size());
    cr_.check_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    report.root_radius_mm = 0;
    for (std::int32_t i = 0; i < f.vessels.nodeCount(); ++i)
      if (f.vessels.isRoot(i) && f.vessels.child0[i] >= 0)
        report.root_radius_mm = std::max(report.root_radius_mm, f.vessels.radius[f.vessels.child0[i]]);
    return f;
  }
  void addStatistics(const GrowthReport&, Json& stats) const override {
    stats["arterial_drains"] = cr_.arterial_drains;
    stats["venous_drains"] = cr_.venous_drains;
    stats["venous_drains_definition"] = "CO2 sources: oxygenated tissue within co2_distance of an artery, and arterial drains the arteries satisfied";
    stats["bifurcations"] = cr_.bifurcations;
    stats["lateral_branches"] = cr_.lateral_branches;
    stats["elongations"] = cr_.elongations;
    stats["outside_rejected"] = cr_.outside_rejected;
    stats["crossing_rejected"] = cr_.crossing_rejected;
    // Each stage's lengths in mm, as the domain's diameter resolved them (the sidecar's parameters give the rule).
    Json lengths = Json::array();
    for (const auto& st : options_.stages)
      lengths.push_back(Json{{"stage", st.name},
                             {"step", quantityJson(st.step, "mm")},
                             {"perception_distance", quantityJson(st.perception_distance, "mm")},
                             {"satisfaction_distance", quantityJson(st.satisfaction_distance, "mm")},
                             {"co2_distance", quantityJson(st.co2_distance, "mm")},
                             {"drain_spacing", quantityJson(st.drain_spacing, "mm")},
                             {"terminal_radius", quantityJson(st.terminal_radius, "mm")},
                             {"surface_depth", quantityJson(st.surface_depth, "mm")}});
    stats["stage_lengths"] = lengths;
    if (setup_.options.avoid_crossing) {
      stats["crossing_pruned"] = cr_.pruned;
      stats["crossing_pruned_definition"] = "branches removed after growth because Murray's law had thickened vessels into each other";
    }
    stats["timing_seconds"] = Json{{"crossing_check", cr_.check_seconds}};  // a time: not sample data
    stats["intersecting_pairs_note"] =
        "colonisation: segments whose capsules overlap, unless the path between them along the tree is shorter than their radii";
  }

  // avoid_crossing: vessels that overlap once Murray's law has thickened them lose the branch
  // with fewer leaves below it (and the chain left dangling), until none overlaps.
  static std::int64_t pruneCrossings(std::vector<VascularTree>& trees, const MurrayLaw& law) {
    std::int64_t pruned = 0;
    for (int round = 0; round < 200; ++round) {
      Forest tmp;
      std::vector<std::int32_t> offset;
      for (std::size_t k = 0; k < trees.size(); ++k) {
        offset.push_back(tmp.vessels.nodeCount());
        tmp.vessels.appendTree(trees[k], int(k));
      }
      auto& t = tmp.vessels;
      const auto pairs = crossingPairs(t);
      if (pairs.empty()) break;
      std::vector<std::int64_t> leaves(std::size_t(t.nodeCount()), 0);
      const auto order = t.topDownOrder();
      for (auto it = order.rbegin(); it != order.rend(); ++it) {
        const auto i = *it;
        leaves[std::size_t(i)] = t.child0[i] < 0 ? 1 : leaves[std::size_t(t.child0[i])] + (t.child1[i] < 0 ? 0 : leaves[std::size_t(t.child1[i])]);
      }
      std::vector<char> removed(std::size_t(t.nodeCount()), 0);
      for (const auto& [x, y] : pairs) {
        const auto victim = leaves[std::size_t(x)] < leaves[std::size_t(y)] || (leaves[std::size_t(x)] == leaves[std::size_t(y)] && x > y) ? x : y;
        if (!removed[std::size_t(victim)]) ++pruned;
        removed[std::size_t(victim)] = 1;
      }
      for (auto i : order)  // subtrees go with their segment
        if (!t.isRoot(i) && removed[std::size_t(t.parent[i])] && !t.isRoot(t.parent[i])) removed[std::size_t(i)] = 1;
      for (auto it = order.rbegin(); it != order.rend(); ++it) {  // and chains left without leaves
        const auto i = *it;
        if (t.isRoot(i) || removed[std::size_t(i)] || t.child0[i] < 0) continue;
        const bool a = removed[std::size_t(t.child0[i])], b = t.child1[i] < 0 || removed[std::size_t(t.child1[i])];
        if (a && b) removed[std::size_t(i)] = 1;
      }
      for (std::size_t k = 0; k < trees.size(); ++k) {
        const auto& old = trees[k];
        VascularTree fresh;
        std::vector<std::int32_t> id(std::size_t(old.nodeCount()), -1);
        for (auto i : old.topDownOrder()) {
          if (removed[std::size_t(offset[k] + i)]) continue;
          id[std::size_t(i)] = fresh.addNode(old.position[i], old.isRoot(i) ? -1 : id[std::size_t(old.parent[i])]);
          fresh.radius[id[std::size_t(i)]] = old.radius[i];
        }
        const auto fo = fresh.topDownOrder();
        for (auto it = fo.rbegin(); it != fo.rend(); ++it) {  // Murray from the leaves, which keep their radius
          const auto i = *it, a = fresh.child0[i], b = fresh.child1[i];
          if (a < 0) continue;
          fresh.radius[i] = b < 0 ? fresh.radius[a] : law.parentRadius(fresh.radius[a], fresh.radius[b]);
        }
        trees[k] = std::move(fresh);
      }
    }
    return pruned;
  }

 private:
  const ColonisationSetup& setup_;
  GrowthDomain loaded_;
  std::unique_ptr<GrowthDomain> world_;
  std::vector<std::unique_ptr<GrowthDomain>> drains_;
  ColonisationOptions options_;
  std::vector<std::string> ids_, kinds_;  // per root of options_
  std::vector<std::unique_ptr<VascularTree>> stumps_;
  mutable ColonisationReport cr_;
};

ColonisationStageSpec readStage(const TomlReader& r, const GrowthMethod& m, const toml::table& t, int index, const std::set<std::string>& regions) {
  checkMethodKeys(r, m, t, "stage");
  ColonisationStageSpec spec;
  spec.line = r.lineOf(&t);
  auto& st = spec.stage;
  st.name = "stage_" + std::to_string(index + 1);
  readSettingsFrom(r, t, "stage", stageSettings(), st, 0);
  readSettingsFrom(r, t, "stage", stageLengthSettings(), spec, 0);
  for (const char* key : {"step", "terminal_radius"})
    if (t.get(key)) spec.lines[key] = r.lineOf(t.get(key));
  spec.domain = regionNames(r, t, "domain", regions);
  return spec;
}

void readRoots(const TomlReader& r, const GrowthMethod& m, const toml::table& tree, ColonisationSetup& s, bool flat) {
  const auto* list = tree.get("inlet");
  const bool initial = r.root().get("initial") != nullptr;
  if (initial && (!list || !list->is_array())) {
    if (s.initial_kind == "vein")
      throw InputError(r.file(), r.lineOf(&tree), "no artery root: with [initial] kind = \"vein\" give the arteries' roots as [[tree.inlet]] tables");
    if (s.options.veins)
      throw InputError(r.file(), r.lineOf(&tree),
                       "no vein root: with [initial] give the veins' roots as [[tree.inlet]] tables (kind = \"vein\"), or set [tree] veins = false");
    return;
  }
  if (!list || !list->is_array()) {
    // One artery at [tree]'s root (the top by default) and, with veins, one vein beside it.
    ColonisationRootSpec a;
    a.id = "artery";
    a.root = readRootOf(r, tree, "tree", s.domain, false);
    a.line = r.lineOf(&tree);
    s.roots.push_back(a);
    if (s.options.veins) {
      if (s.domain.shape == DomainShape::Mask)
        throw InputError(r.file(), r.lineOf(&tree),
                         "a mask domain has no default vein root: give the roots as [[tree.inlet]] tables (kind = \"vein\")");
      ColonisationRootSpec v = a;
      v.id = "vein";
      v.kind = "vein";
      v.beside_artery = true;
      s.roots.push_back(v);
    }
    return;
  }
  for (const char* key : {"root_offset", "root", "root_voxel"})
    if (tree.get(key))
      throw InputError(r.file(), r.lineOf(tree.get(key)),
                       std::string("'") + key + "' in [tree] with [[tree.inlet]] tables: give each root in its table");
  const auto* arr = list->as_array();
  if (!arr->is_array_of_tables() || arr->empty())
    throw InputError(r.file(), r.lineOf(list), "inlet must be an array of tables: write each as [[tree.inlet]]");
  std::map<std::string, int> per_kind, seen;
  for (const auto& node : *arr) {
    const auto& t = *node.as_table();
    checkMethodKeys(r, m, t, "tree.inlet");
    ColonisationRootSpec rs;
    rs.line = r.lineOf(&t);
    rs.kind = choice<std::string>(r, t, "tree.inlet", "kind", "artery", {{"artery", "artery"}, {"vein", "vein"}});
    rs.root = readRootOf(r, t, "tree.inlet", s.domain, true);
    if (const auto* d = t.get("direction")) {
      rs.direction = r.point(d, "direction", flat);
      if (!(norm(rs.direction) > 0)) throw InputError(r.file(), r.lineOf(d), "direction must not be zero");
      rs.has_direction = true;
    }
    ++per_kind[rs.kind];
    s.roots.push_back(rs);
  }
  std::set<std::string> ids;
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const auto& t = *(*arr)[i].as_table();
    auto& rs = s.roots[i];
    const int nth = ++seen[rs.kind];
    rs.id = per_kind[rs.kind] == 1 ? rs.kind : rs.kind + "_" + std::to_string(nth);
    if (t.get("id")) {
      rs.id = r.string(t, "tree.inlet", "id");
      if (const auto why = nameProblem(rs.id, "id"); !why.empty()) throw InputError(r.file(), r.lineOf(t.get("id")), why);
    }
    if (rs.id.empty() || rs.id.size() > 60 || !ids.insert(rs.id).second)
      throw InputError(r.file(), rs.line, "root id '" + rs.id + "' is empty, longer than 60 characters or used twice");
  }
  if (initial) ++per_kind[s.initial_kind];
  if (!per_kind.count("artery")) throw InputError(r.file(), r.lineOf(list), "no artery root: the veins grow to the drains arteries satisfy");
  if (s.options.veins && !per_kind.count("vein"))
    throw InputError(r.file(), r.lineOf(list), "no vein root: add a [[tree.inlet]] with kind = \"vein\", or set [tree] veins = false");
}

std::shared_ptr<const GrowthSetup> readColonisationToml(const TomlReader& r, const GrowthMethod& m) {
  auto s = std::make_shared<ColonisationSetup>();
  s->parameter_file = r.file();
  const auto [dom, tree, ph, domain, flat] = readMethodFileTables(r, m);
  s->domain = domain;
  auto& o = s->options;
  readSettingsFrom(r, tree, "tree", colonisationSettings(), o, domain.voxel_mm);
  if (const auto* node = r.root().get("initial")) {
    auto in = readInitialNetwork(r, m, *node, flat);
    s->initial_file = in.file;
    s->initial = std::move(in.network);
    s->initial_from_corner = in.from_corner;
    s->initial_kind = choice<std::string>(r, *node->as_table(), "initial", "kind", "artery", {{"artery", "artery"}, {"vein", "vein"}});
  }
  readRoots(r, m, tree, *s, flat);
  s->physics_summary = readPhysics(r, colonisationPhysics(), ph);
  o.murray_exponent = s->physics_summary.murray_exponent;
  o.murray_band_edges = s->physics_summary.murray_band_edges;
  o.murray_band_exponents = s->physics_summary.murray_band_exponents;
  s->regions = readRegions(r, m, flat);
  std::set<std::string> names;
  for (const auto& g : s->regions) names.insert(g.name);
  s->avascular = regionNames(r, tree, "avascular", names);
  if (const auto* list = r.root().get("stage")) {
    const auto* arr = list->as_array();
    if (!arr || arr->empty() || !arr->is_array_of_tables())
      throw InputError(r.file(), r.lineOf(list), "stage must be an array of tables: write each as [[stage]]");
    std::set<std::string> stage_names;
    for (const auto& node : *arr) {
      s->stages.push_back(readStage(r, m, *node.as_table(), int(s->stages.size()), names));
      if (!stage_names.insert(s->stages.back().stage.name).second)
        throw InputError(r.file(), s->stages.back().line, "a second stage named '" + s->stages.back().stage.name + "'");
    }
  } else {
    s->stages.push_back(readStage(r, m, toml::table{}, 0, names));  // one stage with every default
  }
  return s;
}

}  // namespace

std::vector<std::string> ColonisationSetup::kinds() const {
  std::vector<std::string> k;
  for (const auto& r : roots)
    if (std::find(k.begin(), k.end(), r.kind) == k.end()) k.push_back(r.kind);
  if (!initial_file.empty() && std::find(k.begin(), k.end(), initial_kind) == k.end()) k.push_back(initial_kind);
  return k;
}

Json ColonisationSetup::describe() const {
  Json j;
  j["method"] = "colonisation";
  j["shape"] = domainShapeName(domain.shape);
  if (domain.shape == DomainShape::Mask) {
    j["mask"] = domain.mask.string();
  } else {
    j[domain.shape == DomainShape::Sphere || domain.shape == DomainShape::Disc ? "radius" : "side"] = quantityJson(domain.size_mm, "mm");
  }
  if (domain.voxel_mm > 0) j["voxel_size"] = quantityJson(domain.voxel_mm, "mm");
  j.update(settingsJson(colonisationSettings(), options));
  j["frame"] = "lengths are their values at the last step; at step t they are scaled by sigma_T / sigma_t";
  Json roots_json = Json::array();
  for (const auto& r : roots) {
    Json e{{"id", r.id}, {"kind", r.kind}};
    if (r.beside_artery)
      e["root_offset"] = "beside the artery's root (0.05 of the diameter along x, moved in until inside)";
    else if (r.root.has_root_offset)
      e["root_offset"] = Json{{"value", {r.root.root_offset_mm.x, r.root.root_offset_mm.y, r.root.root_offset_mm.z}}, {"unit", "mm"}};
    else if (r.root.root_in_mm)
      e["root"] = Json{{"value", {r.root.root_mm.x, r.root.root_mm.y, r.root.root_mm.z}}, {"unit", "mm"}};
    else if (domain.shape == DomainShape::Mask)
      e["root_voxel"] = {r.root.root_voxel.x, r.root.root_voxel.y, r.root.root_voxel.z};
    else
      e["root_offset"] = "the top of the domain (+y)";
    if (r.has_direction) e["direction"] = {r.direction.x, r.direction.y, r.direction.z};
    roots_json.push_back(e);
  }
  j["roots"] = roots_json;
  if (!initial_file.empty())
    j["initial"] = Json{{"file", initial_file.string()},
                        {"kind", initial_kind},
                        {"origin", initial_from_corner ? "corner" : "centre"},
                        {"vessels", initial.tree.segmentCount()},
                        {"roots", initial.tree.roots().size()}};
  Json st = Json::array();
  for (const auto& spec : stages) {
    Json e = settingsJson(stageSettings(), spec.stage);
    e.update(settingsJson(stageLengthSettings(), spec));
    if (!spec.domain.empty()) e["domain"] = spec.domain;
    st.push_back(e);
  }
  j["stages"] = st;
  if (!avascular.empty()) j["avascular"] = avascular;
  j.update(settingsJson(colonisationPhysics(), physics_summary));
  return j;
}

std::unique_ptr<PreparedGrowth> ColonisationSetup::prepare(std::uint64_t memory_limit) const {
  auto loaded = loadDomainSpec(domain, parameter_file, roots.empty() ? RootSpec{} : roots.front().root, memory_limit);
  return std::make_unique<PreparedColonisation>(*this, std::move(loaded));
}

// clang-format off
const GrowthMethod kColonisationMethod{
    "colonisation",
    "space colonisation with physiological constraints (Rauch & Harders 2021): arterial and venous trees grow "
    "together toward oxygen drains sampled in the tissue (oxygenated tissue near the arteries and the drains they satisfy become the veins' CO2 sources), leaves "
    "inside a perception cone, inter-nodes in the Murray-angle shell of a lateral branch, symmetric bifurcations at Murray's "
    "angles when the drains spread wider than φ, radii by Murray's law with κ, tissue growth Δσ per step, in stages with "
    "their own parameters and regions; no node or centreline leaves the domain",
    withRegionParams(withDomainParams("sphere, cube, disc or square (2D), or mask", "masks: drains drawn uniformly, or ∝ the mask value (demand)", joinRows({settingRows(colonisationSettings()), {
        {"tree", "avascular", "region names", "none", "regions no vessel enters (a foveal avascular zone)"},
        {"initial", "file", "path", "none", "an existing network whose trees grow on (stumps; .swc, .vtp, .gxl, .csv, VItA's .cco); every node must lie in the domain"},
        {"initial", "kind", "text", "artery", "the kind of its trees: artery or vein"},
        {"initial", "origin", "text", "centre", "where the file's positions start: centre (of the domain) or corner (of its grid, as angiosynth's graphs write them)"},
        {"initial", "unit", "text", "mm", "length unit of the file: mm, cm, m, um"},
        {"tree.inlet", "id", "text", "its kind (kind_1, kind_2, ... when several)", "the tree's name in graphs and sample.json"},
        {"tree.inlet", "kind", "text", "artery", "artery or vein"},
        {"tree.inlet", "root_offset", "[x, y(, z)] mm", nullptr, "analytic shapes: the root relative to the centre"},
        {"tree.inlet", "root", "[x, y, z] mm", nullptr, "masks: the root in mm in the frame (or root_voxel)"},
        {"tree.inlet", "root_voxel", "[x, y, z] mask voxels", nullptr, "masks: the root in voxels (or root)"},
        {"tree.inlet", "direction", "[x, y(, z)]", "toward the domain's centre", "where the root vessel heads"},
    }, settingRows(colonisationPhysics()), settingRows(stageSettings()), settingRows(stageLengthSettings()), {
        {"stage", "domain", "region names", "the whole domain", "the regions its drains are sampled in (a plexus)"},
    }})), "the region's name, used by [tree] avascular and [[stage]] domain"),
    &readColonisationToml};
// clang-format on

}  // namespace angiosynth
