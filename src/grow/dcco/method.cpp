// Method "dcco": its parameters, TOML reader, description, domains and grow function.
#include <cctype>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "grow/common/method_tables.hpp"
#include "grow/common/region_tables.hpp"
#include "grow/dcco/setup.hpp"
#include "io/growth_domain_files.hpp"
#include "settings/param_checks.hpp"
#include "settings/input_paths.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

Json vectorJson(const Vec3& v) { return Json{{"value", {v.x, v.y, v.z}}, {"unit", "mm"}}; }

constexpr const char* kPdfWords[] = {"uniform", "demand", "gaussian", nullptr};
constexpr const char* kCostWords[] = {"volume", "sprout", nullptr};
constexpr const char* kRoleWords[] = {"", "distribution", "transport", "perforator", nullptr};

// A [[stage]]'s settings but its regions, symmetry and Gaussians.
// clang-format off
const std::vector<Setting<DccoStage>>& stageSettings() {
  using O = DccoStage;
  const auto degrees = [](const char* key, const char* fallback, double hi, const char* meaning, double O::*field) {
    return Setting<O>{.table = "stage", .key = key, .unit = "deg", .fallback = fallback, .meaning = meaning, .field = field,
                      .range = {0, hi}, .fallback_is_value = std::isdigit(static_cast<unsigned char>(*fallback)) != 0};
  };
  static const std::vector<Setting<O>> settings{
      {.table = "stage", .key = "name", .unit = "text", .fallback = "stage_1, stage_2, ...", .meaning = "the stage's name in sample.json",
       .field = &O::name},
      {.table = "stage", .key = "terminals", .unit = "count", .fallback = nullptr, .meaning = "N^t, the terminals this stage adds",
       .field = &O::terminal_count, .range = {1, Limits::kMaxTerminals}},
      {.table = "stage", .key = "pdf", .unit = "text", .fallback = "uniform",
       .meaning = "terminal positions: uniform, demand (∝ the mask value), or gaussian ([[stage.gaussian]])",
       .field = enumChoice<O, &O::pdf, kPdfWords>(), .choices = wordList(kPdfWords), .fallback_is_value = true},
      {.table = "stage", .key = "murray_exponent", .unit = "", .fallback = "3", .meaning = "γ of the bifurcations the stage makes",
       .field = &O::gamma, .range = {Limits::kMinMurray, Limits::kMaxMurray, true, false}, .fallback_is_value = true},
      {.table = "stage", .key = "nu", .unit = "", .fallback = "1", .meaning = "ν in l_lim = l_c (ν / (N_T + 1))^(1/D)",
       .field = &O::nu, .range = {0, 1e6, true, false}, .fallback_is_value = true},
      {.table = "stage", .key = "relaxation", .unit = "", .fallback = "0.9", .meaning = "f_r: l_lim × f_r after draws_before_relaxing rejected points",
       .field = &O::f_r, .range = {0, 1, true, true}, .fallback_is_value = true},
      {.table = "stage", .key = "neighbourhood", .unit = "", .fallback = "8",
       .meaning = "f_n: candidate vessels lie within the box of half-side f_n·l_lim around the terminal",
       .field = &O::f_n, .range = {0, 1e6, true, false}, .fallback_is_value = true},
      {.table = "stage", .key = "lattice", .unit = "count", .fallback = "7", .meaning = "Δv: points per edge of the bifurcation lattice (Δv(Δv+1)/2 − 3 points)",
       .field = &O::delta_v, .range = {3, 50}, .fallback_is_value = true},
      {.table = "stage", .key = "cost", .unit = "text", .fallback = "volume", .meaning = "volume (eq. 10) or sprout (eq. 15)",
       .field = enumChoice<O, &O::cost, kCostWords>(), .choices = wordList(kCostWords), .fallback_is_value = true},
      {.table = "stage", .key = "c_v", .unit = "", .fallback = "50 (2D), 1e4 (3D)", .meaning = "sprout: weight of the added volume / the stage domain's measure",
       .field = &O::c_v, .range = {0, 1e12}, .only_with = {"cost", "sprout"}},
      {.table = "stage", .key = "c_p", .unit = "", .fallback = "0.5", .meaning = "sprout: weight of the parent's radius / r_1",
       .field = &O::c_p, .range = {0, 1e12}, .only_with = {"cost", "sprout"}, .fallback_is_value = true},
      {.table = "stage", .key = "c_d", .unit = "", .fallback = "1", .meaning = "sprout: weight of (new vessel length / l_c)²",
       .field = &O::c_d, .range = {0, 1e12}, .only_with = {"cost", "sprout"}, .fallback_is_value = true},
      degrees("theta_min", "0", 180, "θ_min, bifurcation angle between the split vessel's distal part and the new vessel", &O::theta_min),
      degrees("theta_max", "180 − theta_min", 180, "θ_max", &O::theta_max),
      degrees("phi_min", "0", 90,
              "φ_min, angle between the new vessel and the plane of the split vessel's parts (that of the bifurcation it leaves when they are collinear)",
              &O::phi_min),
      degrees("phi_max", "90", 90, "φ_max", &O::phi_max),
      {.table = "stage", .key = "role", .unit = "text", .fallback = "distribution",
       .meaning = "role of the vessels the stage makes: distribution (inside Ω_t), transport (anywhere), perforator (anywhere, branching only inside Ω_t)",
       .field = enumChoice<O, &O::role, kRoleWords>(), .choices = wordList(kRoleWords), .fallback_is_value = true},
      {.table = "stage", .key = "draws_before_relaxing", .unit = "count", .fallback = "100", .meaning = "N_fail: rejected points before l_lim shrinks",
       .field = &O::draws_before_relaxing, .range = {1, 1000000}, .fallback_is_value = true},
      {.table = "stage", .key = "max_candidates", .unit = "count", .fallback = "64", .meaning = "candidate vessels tried per terminal, nearest first",
       .field = &O::max_candidates, .range = {1, 100000}, .fallback_is_value = true},
  };
  return settings;
}
// clang-format on

// clang-format off
const std::vector<SettingRule<DccoStage>>& stageRules() {
  static const std::vector<SettingRule<DccoStage>> rules{
      {{"theta_max", "theta_min"}, [](const DccoStage& st) { return st.theta_max > st.theta_min ? std::string() : "theta_max must exceed theta_min"; }},
      {{"phi_max", "phi_min"}, [](const DccoStage& st) { return st.phi_max >= st.phi_min ? std::string() : "phi_max must not be below phi_min"; }},
  };
  return rules;
}
// clang-format on

// clang-format off
const std::vector<Setting<DccoOptions>>& dccoSettings() {
  static const std::vector<Setting<DccoOptions>> settings{
      {.table = "tree", .key = "root_radius", .unit = "mm", .fallback = "[initial]: each root vessel's radius in its file; required without it",
       .meaning = "r_1, the fixed radius of the root vessel (of every root of [initial])",
       .field = &DccoOptions::root_radius, .range = {Limits::kMinRadius, Limits::kMaxRadius}, .quantity = Dimension::Length},
  };
  return settings;
}
// clang-format on

// perfusion_flow and perfusion_pressure; the viscosity, a quantity or "pries", is read beside them.
// clang-format off
const std::vector<Setting<PhysicsParameters>>& dccoPhysics() {
  static const std::vector<Setting<PhysicsParameters>> settings = [] {
    auto flow = physicsSetting("perfusion_flow", "500 mL/min");
    flow.meaning = "Q, the inflow, split equally among the terminals";
    auto pressure = physicsSetting("perfusion_pressure", "100 mmHg");
    pressure.meaning = "pressure at the root (the pressures downstream follow from the radii)";
    auto band_edges = physicsSetting("murray_band_edges", "none");
    band_edges.meaning = "parent radii splitting the bifurcations into bands with a Murray exponent each (murray_band_exponents, which then "
                         "replace every stage's murray_exponent): ascending, each at least 1.25 times the one before; γ ramps across an edge "
                         "over ±5 % of its radius";
    return std::vector<Setting<PhysicsParameters>>{flow, pressure, band_edges, physicsSetting("murray_band_exponents", "none")};
  }();
  return settings;
}
// clang-format on

// The domains of one stage on the world's frame; identical region sets share one domain.
struct StageDomains {
  const GrowthDomain* vessels;
  const GrowthDomain* terminals;
};

class PreparedDcco final : public PreparedGrowth {
 public:
  PreparedDcco(const DccoSetup& s, GrowthDomain world) : setup_(s), world_(std::move(world)) {
    if (s.initial_file.empty()) {
      root_ = placeRoot(s.parameter_file, s.root, world_);
    } else {  // the file's positions are relative to the domain's centre, or its grid's corner
      initial_ = s.initial.tree;
      for (auto& p : initial_.position) {
        if (!s.initial_from_corner) p = p + world_.center();
        if (world_.dimension() == 2) p.z = world_.planeZ();
      }
    }
    const auto list = [&](const std::vector<std::string>& names) { return regionsNamed(s.regions, names); };
    const auto key = [](const std::vector<std::string>& in, const std::vector<std::string>& out) {
      std::string k;
      for (const auto& n : in) k += n + ",";
      k += "|";
      for (const auto& n : out) k += n + ",";
      return k;
    };
    for (const auto& st : s.stages) {
      const auto domainOf = [&](const std::vector<std::string>& out, const std::string& what) -> const GrowthDomain* {
        if (st.domain.empty() && out.empty()) return &world_;
        const auto k = key(st.domain, out);
        auto it = cache_.find(k);
        if (it == cache_.end()) {
          try {
            it = cache_.emplace(k, std::make_unique<GrowthDomain>(regionDomain(world_, list(st.domain), list(out), what))).first;
          } catch (const GrowthError& e) { throw InputError(s.parameter_file, st.line, e.what()); }
        }
        return it->second.get();
      };
      auto excluded = st.avascular;
      excluded.insert(excluded.end(), st.carriage.begin(), st.carriage.end());
      StageDomains d{domainOf(st.avascular, "the domain of stage '" + st.stage.name + "'"),
                     domainOf(excluded, "the terminal region of stage '" + st.stage.name + "'")};
      if (st.stage.pdf == TerminalPdf::Demand) {
        if (!demand_) demand_ = std::make_unique<GrowthDomain>(GrowthDomain::mask(world_.frame(), true));
        d.terminals = demand_.get();
      }
      domains_.push_back(d);
    }
  }
  const DemandMap& frame() const override { return world_.frame(); }
  const GrowthDomain* domain() const override { return &world_; }
  void checkFeasibility() const override {
    std::int64_t total = 0;
    for (std::size_t k = 0; k < setup_.stages.size(); ++k) {
      const auto& st = setup_.stages[k];
      total += st.stage.terminal_count;
      std::int64_t inside = 0;
      for (float v : domains_[k].terminals->frame().demand) inside += v > 0;
      // A terminal per voxel at most: finer than its resolution the domain says nothing.
      if (total > inside)
        throw InputError(setup_.parameter_file, st.line,
                         "stage '" + st.stage.name + "' brings the tree to " + std::to_string(total) + " terminals, more than the " +
                             std::to_string(inside) + " voxels of its terminal region; use fewer terminals or a finer voxel_size");
    }
    checkGaussians();
    const double r = setup_.options.root_radius;
    if (!setup_.initial_file.empty()) return;
    if (!(world_.depth(root_) > -1e-6 * world_.frame().voxel_mm))
      throw InputError(setup_.parameter_file, setup_.root.root_line, "the root lies outside the domain");
    if (!(2 * r < 0.5 * std::min({world_.hi().x, world_.hi().y, world_.dimension() == 2 ? world_.hi().x : world_.hi().z})))
      throw InputError(setup_.parameter_file, setup_.root.root_line,
                       "root_radius " + show(r) + " mm is too large for the domain (its frame is " + show3(world_.hi()) + " mm)");
  }
  // The share of each stage's Gaussians inside its terminal region, by draws of their own (the
  // growth's draws are not touched): a mixture whose mass lies outside would have every terminal
  // drawn again and again.
  void checkGaussians() const {
    constexpr int kDraws = 20000;
    constexpr double kLeast = 1e-3;
    for (std::size_t k = 0; k < setup_.stages.size(); ++k) {
      const auto& st = setup_.stages[k].stage;
      if (st.pdf != TerminalPdf::Gaussian || st.gaussians.empty()) continue;
      const GrowthDomain& d = *domains_[k].terminals;
      double total = 0;
      for (const auto& g : st.gaussians) total += g.weight;
      std::mt19937_64 pick(0x9a05517);
      std::normal_distribution<double> normal;
      std::uniform_real_distribution<double> uniform;
      int inside = 0;
      for (int n = 0; n < kDraws; ++n) {
        double u = uniform(pick) * total;
        const GaussianComponent* g = &st.gaussians.back();
        for (const auto& c : st.gaussians)
          if ((u -= c.weight) < 0) {
            g = &c;
            break;
          }
        Vec3 p = world_.center() + g->mean;
        p.x += g->sigma.x * normal(pick);
        p.y += g->sigma.y * normal(pick);
        if (d.dimension() == 3)
          p.z += g->sigma.z * normal(pick);
        else
          p.z = d.planeZ();
        inside += d.depth(p) > 0;
      }
      if (double(inside) < kLeast * kDraws)
        throw InputError(setup_.parameter_file, setup_.stages[k].line,
                         "stage '" + st.name + "': its Gaussians put " + show(100.0 * inside / kDraws) +
                             " % of their mass inside its terminal region (" + std::to_string(inside) + " of " + std::to_string(kDraws) +
                             " draws); allowed: at least " + show(100 * kLeast) +
                             " % (means inside the region, relative to the domain's centre, or wider sigmas)");
    }
  }
  Forest grow(std::uint64_t seed, std::uint64_t sample, GrowthReport& report, const ProgressFn& progress) const override {
    DccoOptions o = setup_.options;
    o.seed = seed;
    o.sample = sample;
    o.root_mm = root_;
    o.world = &world_;
    if (!setup_.initial_file.empty()) {
      o.initial = &initial_;
      o.root_radii = setup_.root_radii;
      for (std::size_t i = 0; i < setup_.initial.ids.size(); ++i)
        o.initial_names.push_back(setup_.initial_file.string() + ":" + std::to_string(setup_.initial.lines[i]) + ": vessel " + setup_.initial.ids[i]);
    }
    o.stages.clear();
    for (std::size_t k = 0; k < setup_.stages.size(); ++k) {
      auto st = setup_.stages[k].stage;
      st.vessels = domains_[k].vessels;
      st.terminals = domains_[k].terminals;
      o.stages.push_back(st);
    }
    dcco_ = {};
    auto tree = growDcco(o, report, dcco_, progress);
    const auto roots = tree.roots().size();
    Forest f = singleTreeForest(std::move(tree), setup_.kind);
    if (roots > 1) {  // one inlet per root of the initial network
      f.trees.clear();
      for (std::size_t k = 0; k < roots; ++k) f.trees.push_back(TreeInfo{"inlet_" + std::to_string(k + 1), setup_.kind, 0});
      assignClassLabels(f.trees);
    }
    return f;
  }
  void addStatistics(const GrowthReport& report, Json& stats) const override {
    Json per = Json::array();
    for (std::size_t k = 0; k < setup_.stages.size() && k < dcco_.stage_terminals.size(); ++k)
      per.push_back(Json{{"name", setup_.stages[k].stage.name}, {"terminals", dcco_.stage_terminals[k]}});
    stats["stages"] = per;
    stats["threshold_relaxations"] = dcco_.threshold_relaxations;
    stats["trial_points"] = dcco_.trial_points;
    stats["trial_points_definition"] = "lattice points costed (Δv(Δv+1)/2 − 3 per versatile candidate vessel)";
    stats["viscosity_iterations"] = dcco_.viscosity_iterations;
    stats["short_segments"] = dcco_.short_segments;
    stats["short_segments_definition"] = "segments not longer than twice their radius";
    stats["outside_segments"] = dcco_.outside_segments;
    stats["asymmetric_bifurcations"] = dcco_.asymmetric_bifurcations;
    stats["asymmetric_bifurcations_definition"] = "bifurcations of two terminal vessels whose radius ratio is not above their stage's δ";
    stats["domain_dimension"] = world_.dimension();
    stats["domain_measure"] = quantityJson(world_.measure(), world_.dimension() == 2 ? "mm^2" : "mm^3");
  }

 private:
  const DccoSetup& setup_;
  GrowthDomain world_;
  Vec3 root_;
  VascularTree initial_;  // in the frame
  std::map<std::string, std::unique_ptr<GrowthDomain>> cache_;
  std::unique_ptr<GrowthDomain> demand_;
  std::vector<StageDomains> domains_;
  mutable DccoReport dcco_;  // of the last grow(), for addStatistics
};

// δ: one number for every level, or a list by bifurcation level (the last repeats).
std::vector<double> readSymmetry(const TomlReader& r, const toml::table& t) {
  const auto* n = t.get("symmetry");
  std::vector<double> v = !n              ? std::vector<double>{0.0}
                          : n->is_array() ? r.numbers(n, "symmetry", 0)
                                          : std::vector<double>{r.number(t, "stage", "symmetry")};
  for (double d : v)
    if (!(d >= 0 && d < 1)) throw InputError(r.file(), r.lineOf(n), "symmetry (δ) values must lie in [0, 1)");
  return v;
}

std::vector<GaussianComponent> readGaussians(const TomlReader& r, const GrowthMethod& m, const toml::table& t, bool flat) {
  std::vector<GaussianComponent> out;
  const auto* list = t.get("gaussian");
  const auto* arr = list ? list->as_array() : nullptr;
  if (!arr || arr->empty() || !arr->is_array_of_tables())
    throw InputError(r.file(), r.lineOf(list ? list : &t), "pdf = \"gaussian\" needs [[stage.gaussian]] tables (mean, sigma, weight)");
  for (const auto& node : *arr) {
    const auto& g = *node.as_table();
    checkMethodKeys(r, m, g, "stage.gaussian");
    GaussianComponent c;
    c.mean = g.get("mean") ? r.point(g.get("mean"), "mean (mm from the domain's centre)", flat) : Vec3();
    c.sigma = r.point(r.need(g, "stage.gaussian", "sigma"), "sigma (mm per axis)", flat);
    if (flat) c.sigma.z = 1;
    if (!(c.sigma.x > 0 && c.sigma.y > 0 && c.sigma.z > 0))
      throw InputError(r.file(), r.lineOf(g.get("sigma")), "sigma must be positive on every axis");
    c.weight = declaredNumber(r, m, g, "stage.gaussian", "weight");
    checkRange(c.weight, 0, true, 1e12, false, r.at(g, "weight"), "weight");
    out.push_back(c);
  }
  return out;
}

DccoStageSpec readStage(const TomlReader& r, const GrowthMethod& m, const toml::table& t, int index, bool flat,
                        const std::set<std::string>& regions) {
  checkMethodKeys(r, m, t, "stage");
  DccoStageSpec s;
  s.line = r.lineOf(&t);
  auto& st = s.stage;
  st.name = "stage_" + std::to_string(index + 1);
  readSettingsFrom(r, t, "stage", stageSettings(), st, 0);
  s.domain = regionNames(r, t, "domain", regions);
  s.avascular = regionNames(r, t, "avascular", regions);
  s.carriage = regionNames(r, t, "carriage", regions);
  if (st.pdf == TerminalPdf::Gaussian)
    st.gaussians = readGaussians(r, m, t, flat);
  else if (t.get("gaussian"))
    throw InputError(r.file(), r.lineOf(t.get("gaussian")), "[[stage.gaussian]] needs pdf = \"gaussian\"");
  st.delta = readSymmetry(r, t);
  // Maso Talou et al. 2021 Fig. 3: c_v 0.5e2 in 2D, 1e4 in 3D.
  if (st.cost == StageCost::Sprout && !t.get("c_v")) st.c_v = flat ? 50.0 : 1e4;
  if (!t.get("theta_max")) st.theta_max = 180 - st.theta_min;  // Table 1: the supplement
  checkRules(stageRules(), st, keysIn(r, t), Where{r.file(), s.line});
  return s;
}

// [initial] and [[initial.vessel]]: the network growth continues from.
void readInitial(const TomlReader& r, const GrowthMethod& m, DccoSetup& s, bool flat, const toml::table* root_radius) {
  const auto* node = r.root().get("initial");
  if (!node) {
    if (!root_radius) throw InputError(r.file(), 0, "[tree] root_radius is required (the fixed radius of the root vessel)");
    return;
  }
  auto in = readInitialNetwork(r, m, *node, flat);
  const auto* t = node->as_table();
  s.initial_file = in.file;
  s.initial = std::move(in.network);
  s.initial_from_corner = in.from_corner;
  auto& tree = s.initial.tree;
  const auto branchingOf = [&](const toml::table& tab, const std::string& table, Branching fallback) {
    return choice<Branching>(
        r, tab, table, "branching", fallback,
        {{"none", Branching::None}, {"distal", Branching::Distal}, {"fixed", Branching::Fixed}, {"versatile", Branching::Versatile}});
  };
  const auto roleOf = [&](const toml::table& tab, const std::string& table, VesselRole fallback) {
    return choice<VesselRole>(
        r, tab, table, "role", fallback,
        {{"distribution", VesselRole::Distribution}, {"transport", VesselRole::Transport}, {"perforator", VesselRole::Perforator}});
  };
  const auto default_branching = branchingOf(*t, "initial", Branching::None);
  const auto default_role = roleOf(*t, "initial", VesselRole::Transport);
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i) {
    if (tree.isRoot(i)) continue;
    if (tree.branching[i] == 0) tree.branching[i] = std::uint8_t(default_branching);
    if (tree.role[i] == 0) tree.role[i] = std::uint8_t(default_role);
  }
  std::map<std::string, std::int32_t> by_id;
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i)
    if (!tree.isRoot(i)) by_id[s.initial.ids[std::size_t(i)]] = i;
  if (const auto* list = t->get("vessel")) {
    const auto* arr = list->as_array();
    if (!arr || !arr->is_array_of_tables())
      throw InputError(r.file(), r.lineOf(list), "vessel must be an array of tables: write each as [[initial.vessel]]");
    std::map<std::string, int> given;  // id → the line of its [[initial.vessel]]
    for (const auto& v : *arr) {
      const auto& vt = *v.as_table();
      checkMethodKeys(r, m, vt, "initial.vessel");
      const auto* idn = r.need(vt, "initial.vessel", "id");
      const std::string id = idn->is_integer() ? std::to_string(*idn->value<std::int64_t>()) : r.string(vt, "initial.vessel", "id");
      if (const auto [at, added] = given.emplace(id, r.lineOf(idn)); !added)
        throw InputError(
            r.file(), r.lineOf(idn),
            "vessel id " + id + " is set again (first on line " + std::to_string(at->second) + "); allowed: one [[initial.vessel]] per vessel");
      const auto it = by_id.find(id);
      if (it == by_id.end())
        throw InputError(
            r.file(), r.lineOf(idn),
            "vessel id " + id + " is not a vessel of " + s.initial_file.string() + " (ids: a .cco vessel's, an SWC sample's that ends the segment)");
      const auto i = it->second;
      tree.branching[i] = std::uint8_t(branchingOf(vt, "initial.vessel", Branching(tree.branching[i])));
      tree.role[i] = std::uint8_t(roleOf(vt, "initial.vessel", VesselRole(tree.role[i])));
      if (vt.get("outflow")) {
        const double f = r.number(vt, "initial.vessel", "outflow");
        checkRange(f, 0, false, 1, true, r.at(vt, "outflow"), "outflow (fraction of the inflow Q)");
        tree.outflow[i] = f;
      }
    }
  }
  double reserved = 0;
  std::int64_t common = 0;
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i) {
    if (tree.outflow[i] > 0 && !tree.isTerminal(i))
      throw InputError(s.initial_file.string(), s.initial.lines[std::size_t(i)],
                       "vessel " + s.initial.ids[std::size_t(i)] + " has an outflow but branches; outflows are for terminal vessels");
    if (tree.outflow[i] > 0)
      reserved += tree.outflow[i];
    else
      common += tree.isTerminal(i);
  }
  if (!(reserved < 1) || common == 0)
    throw InputError(r.file(), r.lineOf(node),
                     "the outflows add up to " + show(reserved) + " of Q with " + std::to_string(common) +
                         " terminals left to perfuse the domain; they must add up to less than 1 and leave a terminal without outflow");
  // Each root's fixed radius: [tree] root_radius for all, else the file's root vessel radius.
  for (auto root : tree.roots()) {
    const auto seg = tree.child0[root];
    if (seg < 0) throw InputError(s.initial_file.string(), s.initial.lines[std::size_t(root)], "a root without a vessel");
    double radius = root_radius ? s.options.root_radius : tree.radius[seg];
    if (!root_radius && !(radius > 0))
      throw InputError(s.initial_file.string(), s.initial.lines[std::size_t(seg)],
                       "root vessel " + s.initial.ids[std::size_t(seg)] + " has no radius; give [tree] root_radius");
    s.root_radii.push_back(radius);
  }
  s.options.root_radius = *std::max_element(s.root_radii.begin(), s.root_radii.end());
  if (flat)  // one plane (readInitialNetwork checked): the domain's
    for (auto& p : tree.position) p.z = 0;
}

std::shared_ptr<const GrowthSetup> readDccoToml(const TomlReader& r, const GrowthMethod& m) {
  auto s = std::make_shared<DccoSetup>();
  s->parameter_file = r.file();
  const auto [dom, tree, ph, domain, flat] = readMethodFileTables(r, m);
  s->domain = domain;
  s->root = readRootOf(r, tree, "tree", s->domain, false);
  auto& o = s->options;
  readSettingsFrom(r, tree, "tree", dccoSettings(), o, 0);
  readInitial(r, m, *s, flat, tree.get("root_radius") ? &tree : nullptr);
  if (tree.get("kind")) {
    s->kind = r.string(tree, "tree", "kind");
    if (const auto why = nameProblem(s->kind, "kind"); !why.empty()) throw InputError(r.file(), r.lineOf(tree.get("kind")), why);
  }
  // [physics]: viscosity "pries" or a quantity.
  if (const auto* v = ph.get("viscosity"); v && v->is_string() && *v->value<std::string>() == "pries") {
    o.viscosity.model = ViscosityModel::Pries;
  } else {
    o.viscosity.constant = declaredQuantity(r, m, ph, "physics", "viscosity", Dimension::Viscosity);
    checkRange(o.viscosity.constant, Limits::kMinViscosity, false, Limits::kMaxViscosity, false, r.at(ph, "viscosity"), "viscosity (Pa*s)");
    r.forbid(ph, "physics", {"pries_exponent"}, "is for viscosity = \"pries\"");
  }
  o.viscosity.exponent = declaredNumber(r, m, ph, "physics", "pries_exponent");
  checkRange(o.viscosity.exponent, 0.1, false, 2, false, r.at(ph, "pries_exponent"), "pries_exponent");
  if (o.viscosity.model == ViscosityModel::Pries && !(o.root_radius > 0.01))
    throw InputError(r.file(), r.lineOf(tree.get("root_radius")), "root_radius below 10 µm: Pries' law holds for diameters of about 10 µm and more");
  s->physics_summary = readPhysics(r, dccoPhysics(), ph);
  o.flow = s->physics_summary.perfusion_flow;
  o.root_pressure = s->physics_summary.perfusion_pressure;
  o.murray_band_edges = s->physics_summary.murray_band_edges;
  o.murray_band_exponents = s->physics_summary.murray_band_exponents;
  s->regions = readRegions(r, m, flat);
  std::set<std::string> region_names;
  for (const auto& g : s->regions) region_names.insert(g.name);
  const auto* list = r.root().get("stage");
  const auto* arr = list ? list->as_array() : nullptr;
  if (!arr || arr->empty() || !arr->is_array_of_tables())
    throw InputError(r.file(), r.lineOf(list ? list : &tree), "method dcco needs at least one [[stage]] table (terminals, domain, parameters)");
  std::set<std::string> stage_names;
  for (const auto& node : *arr) {
    s->stages.push_back(readStage(r, m, *node.as_table(), int(s->stages.size()), flat, region_names));
    const auto& st = s->stages.back();
    if (!stage_names.insert(st.stage.name).second) throw InputError(r.file(), st.line, "a second stage named '" + st.stage.name + "'");
    if (st.stage.pdf == TerminalPdf::Demand &&
        (s->domain.shape != DomainShape::Mask || !st.domain.empty() || !st.avascular.empty() || !st.carriage.empty()))
      throw InputError(r.file(), st.line,
                       "pdf = \"demand\" draws terminals ∝ the mask value of the whole domain: it needs shape = \"mask\" and a stage without domain, "
                       "avascular or carriage regions");
  }
  if (s->stages.size() > 30000) throw InputError(r.file(), s->stages.back().line, "more than 30000 stages");
  auto& p = s->physics_summary;
  p.murray_exponent = s->stages.front().stage.gamma;
  p.viscosity = o.viscosity.constant;
  p.total_terminals = s->terminals();
  return s;
}

}  // namespace

std::int64_t DccoSetup::terminals() const {
  std::int64_t n = 0;
  for (const auto& st : stages) n += st.stage.terminal_count;
  return n;
}

Json DccoSetup::describe() const {
  const auto& d = domain;
  const auto& o = options;
  Json j;
  j["method"] = "dcco";
  describeDomainAndRoot(d, root, j);
  j["kind"] = kind;
  if (!initial_file.empty()) {
    Json init{{"file", initial_file.string()},
              {"origin", initial_from_corner ? "corner" : "centre"},
              {"vessels", initial.tree.segmentCount()},
              {"roots", root_radii.size()}};
    Json radii = Json::array(), outlets = Json::array();
    for (double v : root_radii) radii.push_back(v);
    init["root_radii_mm"] = radii;
    for (std::int32_t i = 0; i < initial.tree.nodeCount(); ++i)
      if (initial.tree.outflow[i] > 0) outlets.push_back(Json{{"vessel", initial.ids[std::size_t(i)]}, {"outflow", initial.tree.outflow[i]}});
    init["outlets"] = outlets;
    j["initial"] = init;
  }
  j.update(settingsJson(dccoSettings(), o));
  j.update(settingsJson(dccoPhysics(), physics_summary));
  if (o.viscosity.model == ViscosityModel::Pries) {
    j["viscosity"] = "pries";
    j["pries_exponent"] = o.viscosity.exponent;
  } else {
    j["viscosity"] = quantityJson(o.viscosity.constant, "Pa*s");
  }
  j["terminals"] = terminals();
  Json regs = Json::array();
  for (const auto& g : regions) {
    Json e{{"name", g.name}, {"shape", regionShapeName(g.shape)}, {"centre", vectorJson(g.centre)}};
    if (g.radius > 0) e["radius"] = quantityJson(g.radius, "mm");
    if (g.outer > 0) {
      e["inner_radius"] = quantityJson(g.inner, "mm");
      e["outer_radius"] = quantityJson(g.outer, "mm");
    }
    if (g.size.x > 0) e["size"] = vectorJson(g.size);
    regs.push_back(e);
  }
  if (!regions.empty()) j["regions"] = regs;
  Json stages_json = Json::array();
  for (const auto& sp : stages) {
    const auto& st = sp.stage;
    Json e = settingsJson(stageSettings(), st);
    e["domain"] = sp.domain.empty() ? Json("the whole domain") : Json(sp.domain);
    if (!sp.avascular.empty()) e["avascular"] = sp.avascular;
    if (!sp.carriage.empty()) e["carriage"] = sp.carriage;
    if (st.pdf == TerminalPdf::Gaussian) {
      Json gs = Json::array();
      for (const auto& g : st.gaussians) gs.push_back(Json{{"mean", vectorJson(g.mean)}, {"sigma", vectorJson(g.sigma)}, {"weight", g.weight}});
      e["gaussians"] = gs;
    }
    e["symmetry"] = st.delta;
    stages_json.push_back(e);
  }
  j["stages"] = stages_json;
  return j;
}

std::vector<std::filesystem::path> DccoSetup::inputs() const {
  auto in = domainInputs(domain);
  if (!initial_file.empty()) in.push_back(initial_file);
  return in;
}

std::unique_ptr<PreparedGrowth> DccoSetup::prepare(std::uint64_t memory_limit) const {
  return std::make_unique<PreparedDcco>(*this, loadDomainSpec(domain, parameter_file, root, memory_limit));
}

// clang-format off
const GrowthMethod kDccoMethod{
    "dcco",
    "domain-constrained CCO in stages (Maso Talou et al. 2021): each [[stage]] adds its terminals in its own "
    "region with its own parameters, cost (volume or sprouting) and vessel role; bifurcations on DCCO's triangle lattice, "
    "a fixed root radius and inflow, constant or Pries viscosity, angle and symmetry limits, no overlapping vessels",
    withRegionParams(withDomainParams("sphere, cube, disc or square (2D), or mask: the region every vessel stays in",
                     "masks: terminals of stages over the whole domain drawn uniformly, or ∝ the mask value (demand; as [[stage]] pdf = \"demand\")", joinRows({{
    }, settingRows(dccoSettings()), {
        {"initial", "file", "path", "none", "an existing network the growth continues (.cco of VItA, .swc, .vtp of VItA or VTK, angiosynth's .gxl or nodes/edges .csv); each root is an inlet"},
        {"initial", "origin", "text", "centre", "where the file's positions start: centre (of the domain) or corner (of its grid, as angiosynth's graphs write them)"},
        {"initial", "unit", "text", "mm", "length unit of the file: mm, cm, m, um"},
        {"initial", "branching", "text", "none", "branching of its vessels where the file gives none: none, distal, fixed, versatile"},
        {"initial", "role", "text", "transport", "role of its vessels where the file gives none: distribution, transport, perforator"},
        {"initial.vessel", "id", "id", nullptr, "a vessel of the file (.cco vessel id, SWC id of the sample ending it)"},
        {"initial.vessel", "branching", "text", "the file's", "its branching: none, distal, fixed, versatile"},
        {"initial.vessel", "role", "text", "the file's", "its role"},
        {"initial.vessel", "outflow", "", "0", "a terminal's prescribed outflow as a fraction of Q (the other terminals share the rest)"},
        {"tree", "kind", "text", "artery", "the tree's kind in labels and graphs"},
        {"physics", "viscosity", "Pa*s or \"pries\"", "0.0036 Pa*s", "constant blood viscosity, or \"pries\": Pries' in-vivo law η(D) at haematocrit 0.45 (eqs. 8–9), solved with the radii to |Δη/η| < 1e-6"},
        {"physics", "pries_exponent", "", "0.645", "the exponent of D in Pries' law (the paper prints 0.64)"},
    }, settingRows(dccoPhysics()), settingRows(stageSettings()), {
        {"stage", "domain", "region names", "the whole [domain]", "Ω_t, the union of these regions"},
        {"stage", "avascular", "region names", "none", "regions no vessel of the stage enters and no terminal lies in"},
        {"stage", "carriage", "region names", "none", "regions vessels may cross but no terminal lies in"},
        {"stage", "symmetry", "number or list", "0", "δ: min/max radius of a new bifurcation's branches must exceed it; a list gives δ per bifurcation level (the last repeats)"},
        {"stage.gaussian", "mean", "[x, y(, z)] mm", "[0, 0, 0]", "centre of the Gaussian, relative to the domain's centre"},
        {"stage.gaussian", "sigma", "[x, y(, z)] mm", nullptr, "standard deviation per axis"},
        {"stage.gaussian", "weight", "", "1", "its weight in the mixture"},
    }})), "the region's name, used by [[stage]] domain, avascular and carriage"),
    &readDccoToml};
// clang-format on

}  // namespace angiosynth
