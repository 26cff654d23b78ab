// Method "cco": its parameters, TOML reader, description, domain and grow function.
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "grow/cco/part_file.hpp"
#include "grow/cco/setup.hpp"
#include "grow/common/feasibility.hpp"
#include "grow/common/method_tables.hpp"
#include "io/growth_domain_files.hpp"
#include "io/map_files.hpp"
#include "settings/input_paths.hpp"

namespace angiosynth {

constexpr const char* kSpacingWords[] = {"terminals", "segments", nullptr};
constexpr const char* kBifurcationWords[] = {"exact", "kamiya", nullptr};

// [tree]'s settings of one tree or of each kind of a forest.
// clang-format off
const std::vector<Setting<CcoOptions>>& ccoSettings() {
  using O = CcoOptions;
  static const std::vector<Setting<O>> settings{
      {.table = "tree", .key = "terminals", .unit = "count", .fallback = nullptr, .meaning = "N, the number of terminal segments",
       .field = &O::terminals, .range = {1, Limits::kMaxTerminalsInParts}},
      {.table = "tree", .key = "closest_neighbours", .unit = "count", .fallback = "20", .meaning = "ν, the nearest segments tried per terminal",
       .field = &O::closest_neighbours, .range = {1, Limits::kMaxNeighbours}, .fallback_is_value = true},
      {.table = "tree", .key = "max_closest_neighbours", .unit = "count", .fallback = "closest_neighbours",
       .meaning = "in 3D, ν doubles up to this while no candidate connects (never in 2D); at least closest_neighbours; equal to it (the default), "
                  "ν stays, as doubling joins points to far segments by long, heavy connections",
       .field = &O::max_neighbours, .range = {1, Limits::kMaxNeighbours * 64}},
      {.table = "tree", .key = "kamiya_iterations", .unit = "count", .fallback = "100", .meaning = "iterations of Kamiya's bifurcation solver",
       .field = &O::kamiya_iterations, .range = {1, 100000}, .fallback_is_value = true},
      {.table = "tree", .key = "kamiya_tolerance", .unit = "", .fallback = "1e-6", .meaning = "its step, relative to the three lengths, at convergence",
       .field = &O::kamiya_tolerance, .range = {0, 1, true, false}, .fallback_is_value = true},
      {.table = "tree", .key = "draws_before_relaxing", .unit = "count", .fallback = "100", .meaning = "failed draws before the distance threshold shrinks",
       .field = &O::draws_before_relaxing, .range = {1, 1000000}, .fallback_is_value = true},
      {.table = "tree", .key = "relaxation", .unit = "", .fallback = "0.9", .meaning = "the factor on the distance threshold after such a run",
       .field = &O::relaxation, .range = {0, 1, true, false}, .fallback_is_value = true},
      {.table = "tree", .key = "spacing_from", .unit = "terminals/segments", .fallback = "terminals",
       .meaning = "a drawn terminal keeps delta_max from the terminal points (Kerautret et al.'s Algorithm 2, OpenCCO's code) or from every "
                  "segment (its §3.3.2 wording; evenly spread terminals, long connections, 10 % more volume); either way it lies outside every vessel",
       .field = enumChoice<O, &O::spacing_from, kSpacingWords>(), .choices = wordList(kSpacingWords), .fallback_is_value = true},
      {.table = "tree", .key = "bifurcation", .unit = "exact/kamiya", .fallback = "exact",
       .meaning = "each connection's bifurcation: the lighter of Kamiya's fixed point and the exact minimum of the tree's volume (which "
                  "slides along l = 2r), or Kamiya's point alone (as in OpenCCO, Kerautret et al.)",
       .field = enumChoice<O, &O::bifurcation, kBifurcationWords>(), .choices = wordList(kBifurcationWords), .fallback_is_value = true},
      {.table = "tree", .key = "organ_scale", .unit = "true/false", .fallback = "false",
       .meaning = "for 10^5 to 10^6 terminals: each terminal's distance threshold starts where the last connection's stood (not at "
                  "delta_max), the vessels' relative radii are refreshed as the tree grows by 1/256 of itself (not every 64 terminals), and "
                  "only the 4 lightest of Kamiya's bifurcations and the 4 nearest segments without one are refined; time per terminal grows "
                  "slowly, volume within 1 % (docs/benchmarks.md); false: as Karch et al. 1999",
       .field = &O::organ_scale, .fallback_is_value = true},
  };
  return settings;
}
// clang-format on

// [tree]'s settings of a tree grown in parts.
// clang-format off
const std::vector<Setting<CcoDecompositionOptions>>& ccoDecompositionSettings() {
  using O = CcoDecompositionOptions;
  static const std::vector<Setting<O>> settings{
      {.table = "tree", .key = "parts", .unit = "count", .fallback = "0",
       .meaning = "K >= 2: the tree is grown in K parts by domain decomposition (after Cury et al. 2021): a trunk of K terminals, then each "
                  "part in its terminal's territory with its share of the terminals and flow (in parallel, or as separate tasks with "
                  "`generate --part`), then joined, solved and checked whole; for 10^6 terminals and more (about 25 % more volume than one "
                  "tree, docs/benchmarks.md). 0: one tree. A single inlet only",
       .field = &O::parts, .range = {0, 4096},
       .problem = [](double v) { return v == 1 ? std::string("parts = 1 is one tree grown the long way; allowed: 0 (one tree) or 2 to 4096") : std::string(); },
       .fallback_is_value = true},
  };
  return settings;
}
// clang-format on

// clang-format off
const std::vector<SettingRule<CcoOptions>>& ccoRules() {
  static const std::vector<SettingRule<CcoOptions>> rules{
      {{"max_closest_neighbours"}, [](const CcoOptions& o) {
         return o.max_neighbours >= o.closest_neighbours
                    ? std::string()
                    : "max_closest_neighbours = " + std::to_string(o.max_neighbours) + " is below closest_neighbours = " +
                          std::to_string(o.closest_neighbours) + "; allowed: at least closest_neighbours";
       }}};
  return rules;
}
// clang-format on

// Kerautret et al. (OpenCCO) §5 after Karch 1999: 3.6 cP, written in Pa*s, since "3.6 cP" parses one ulp off 3.6e-3.
// clang-format off
const std::vector<Setting<PhysicsParameters>>& ccoPhysics() {
  static const std::vector<Setting<PhysicsParameters>> settings{
      physicsSetting("murray_exponent", "3"), physicsSetting("murray_band_edges", "none"), physicsSetting("murray_band_exponents", "none"),
      physicsSetting("viscosity", "0.0036 Pa*s"), physicsSetting("perfusion_pressure", "100 mmHg"),
      physicsSetting("terminal_pressure", "60 mmHg"), physicsSetting("perfusion_flow", "500 mL/min")};
  return settings;
}
// clang-format on

namespace {

using Json = nlohmann::ordered_json;

// Defaults of a vein's pressures (venules about 20 mmHg, a large vein about 5 mmHg).
constexpr const char* kVeinRootPressure = "5 mmHg";
constexpr const char* kVeinTerminalPressure = "20 mmHg";

// The kinds of the inlets in order of first appearance: one system of competing trees each.
std::vector<std::string> kindsOf(const std::vector<CcoInletSpec>& inlets) {
  std::vector<std::string> kinds;
  for (const auto& in : inlets)
    if (std::find(kinds.begin(), kinds.end(), in.kind) == kinds.end()) kinds.push_back(in.kind);
  return kinds;
}

class PreparedCco final : public PreparedGrowth {
 public:
  // The trees in inlet order as the forest, named and labelled by their inlets.
  Forest forestOf(std::vector<VascularTree> trees) const {
    Forest f;
    for (std::size_t k = 0; k < trees.size(); ++k) {
      f.vessels.appendTree(trees[k], int(k));
      f.trees.push_back(TreeInfo{setup_.inlets[k].id, setup_.inlets[k].kind, 0});
    }
    assignClassLabels(f.trees);
    return f;
  }
  // The decomposition of the (single) tree of (seed, sample).
  CcoDecompositionOptions decomposition(std::uint64_t seed, std::uint64_t sample) const {
    CcoDecompositionOptions d = setup_.decomposition;
    d.cco = setup_.cco;
    d.cco.seed = seed;
    d.cco.sample = sample;
    d.cco.root_mm = inlets_.front().root_mm;
    return d;
  }
  // Of what a part depends on: the resolved parameters, seed and sample.
  std::uint64_t fingerprint(std::uint64_t seed, std::uint64_t sample) const {
    const std::string text = setup_.describe().dump() + "|" + std::to_string(seed) + "|" + std::to_string(sample);
    return hashName(text.data(), text.size());
  }
  // The inlets' roots are placed (and checked inside the domain) once, for every sample.
  PreparedCco(const CcoSetup& s, GrowthDomain d) : setup_(s), domain_(std::move(d)) {
    const auto kinds = kindsOf(s.inlets);
    systems_ = kinds.size();
    for (const auto& in : s.inlets) {
      CcoInlet g;
      g.root_mm = placeRoot(s.parameter_file, in.root, domain_);
      g.system = int(std::find(kinds.begin(), kinds.end(), in.kind) - kinds.begin());
      g.share = in.share;
      g.root_pressure = in.root_pressure;
      g.terminal_pressure = in.terminal_pressure;
      inlets_.push_back(g);
    }
  }
  const DemandMap& frame() const override { return domain_.frame(); }
  void checkFeasibility() const override {
    std::int64_t inside = 0;  // voxels of the domain
    for (float v : domain_.frame().demand) inside += v > 0;
    const auto& c = setup_.cco;
    if (setup_.decomposition.parts == 0 && double(c.terminals) > Limits::kMaxTerminals)
      throw InputError(setup_.parameter_file, setup_.terminals_line,
                       "terminals = " + std::to_string(c.terminals) + " in one tree; allowed: up to " + show(Limits::kMaxTerminals) + ", or up to " +
                           show(Limits::kMaxTerminalsInParts) + " grown in parts ([tree] parts = K)");
    if (setup_.decomposition.parts > c.terminals)
      throw InputError(setup_.parameter_file, setup_.terminals_line,
                       std::to_string(c.terminals) + " terminals in " + std::to_string(setup_.decomposition.parts) +
                           " parts; allowed: at least one terminal per part (more terminals or fewer parts)");
    const std::int64_t total = c.terminals * std::int64_t(systems_);
    // A terminal per voxel of the domain at most: finer than its resolution the mask says nothing.
    if (total > inside)
      throw InputError(setup_.parameter_file, setup_.terminals_line,
                       std::to_string(total) + " terminals" + (systems_ > 1 ? " (" + std::to_string(c.terminals) + " per kind)" : "") +
                           " exceed the " + std::to_string(inside) + " voxels of the domain; use fewer terminals or a finer voxel_size (mask)");
    // Every kind fills the domain beside the others: each has its share of the room, and its
    // thickest vessels come from its smallest pressure drop.
    const double room = domain_.measure() / double(systems_);
    std::vector<double> root_radius;
    for (std::size_t i = 0; i < inlets_.size(); ++i) {
      const auto p = inletPhysics(c.physics, inlets_[i].root_pressure, inlets_[i].terminal_pressure);
      checkVesselRoom(p, c.terminals, room, domain_.dimension(), setup_.parameter_file,
                      setup_.inlet_tables ? setup_.inlets[i].line : setup_.terminals_line);
      root_radius.push_back(estimateRadii(p, c.terminals, room, domain_.dimension()).root);
    }
    // Two roots closer than their root vessels are thick cannot both start a tree.
    for (std::size_t i = 0; i < inlets_.size(); ++i)
      for (std::size_t j = i + 1; j < inlets_.size(); ++j) {
        const double ri = root_radius[i], rj = root_radius[j], apart = distance(inlets_[i].root_mm, inlets_[j].root_mm);
        if (!(apart > 2 * (ri + rj)))
          throw InputError(setup_.parameter_file, setup_.inlets[j].root.root_line ? setup_.inlets[j].root.root_line : setup_.inlets[j].line,
                           "the roots of inlets '" + setup_.inlets[i].id + "' and '" + setup_.inlets[j].id + "' lie " + show(apart) +
                               " mm apart; their root vessels (radius about " + show(ri) + " and " + show(rj) + " mm) need more than " +
                               show(2 * (ri + rj)) + " mm; move them apart");
      }
  }
  const GrowthDomain* domain() const override { return &domain_; }
  Forest grow(std::uint64_t seed, std::uint64_t sample, GrowthReport& report, const ProgressFn& progress) const override {
    CcoOptions co = setup_.cco;
    co.seed = seed;
    co.sample = sample;
    if (parts() > 0) {
      const auto d = decomposition(seed, sample);
      VascularTree t = growCcoDecomposed(domain_, d, report, progress);
      return forestOf({std::move(t)});
    }
    return forestOf(growCcoForest(domain_, co, inlets_, report, progress));
  }
  int parts() const override { return setup_.decomposition.parts; }
  PartTaskSummary growPart(std::uint64_t seed, std::uint64_t sample, int index, const std::filesystem::path& dir) const override {
    const auto d = decomposition(seed, sample);
    const CcoPartKey key{fingerprint(seed, sample), index, d.parts};
    PartTaskSummary out;
    out.file = ccoPartFile(dir, index);
    if (const auto kept = readCcoPartFile(out.file, key)) {
      out.resumed = true;
      for (std::int32_t i = 1; i < kept->tree.nodeCount(); ++i) out.terminals += kept->tree.isTerminal(i);
      out.seconds = kept->seconds;
      return out;
    }
    const CcoTrunk trunk = planCcoTrunk(domain_, d);
    const CcoPart part = growCcoPart(domain_, trunk, index, d);
    writeCcoPartFile(out.file, part, key);
    out.terminals = part.tree.terminalCount();
    out.seconds = part.seconds;
    return out;
  }
  Forest joinParts(std::uint64_t seed, std::uint64_t sample, const std::filesystem::path& dir, GrowthReport& report,
                   const ProgressFn& progress) const override {
    const auto d = decomposition(seed, sample);
    const auto t0 = std::chrono::steady_clock::now();
    const CcoTrunk trunk = planCcoTrunk(domain_, d);
    CcoDecompositionSummary sum;
    sum.trunk_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<CcoPart> parts;
    std::vector<int> missing;
    for (int k = 0; k < d.parts; ++k) {
      auto p = readCcoPartFile(ccoPartFile(dir, k), CcoPartKey{fingerprint(seed, sample), k, d.parts});
      if (!p) {
        missing.push_back(k);
        continue;
      }
      sum.slowest_part_seconds = std::max(sum.slowest_part_seconds, p->seconds);
      sum.parts_seconds += p->seconds;
      parts.push_back(std::move(*p));
      if (progress) progress(k + 1, d.parts);
    }
    if (!missing.empty()) {
      std::string list;
      for (std::size_t i = 0; i < missing.size() && i < 20; ++i) list += (i ? ", " : "") + std::to_string(missing[i]);
      if (missing.size() > 20) list += ", …";
      throw InputError(dir.string(), 0,
                       "holds no file of part(s) " + list + " of " + std::to_string(d.parts) +
                           "; allowed: the join once every `generate --part I` task has finished (rerun those tasks)");
    }
    VascularTree t = joinCcoPartsRegrowing(domain_, trunk, parts, d, sum);
    report = decomposedReport(parts, sum, t);
    return forestOf({std::move(t)});
  }
  void addStatistics(const GrowthReport& report, Json& stats) const override {
    if (const auto& d = report.decomposition) {
      stats["decomposition"] =
          Json{{"parts", d->parts},
               {"regrown_parts", d->regrown_parts},
               {"part_radius_scale", {d->smallest_part_scale, d->largest_part_scale}},
               {"part_radius_scale_definition", "each part's radii in the whole tree over those it was grown with (at most 1: its own checks hold)"},
               {"trunk_radius_share", d->largest_trunk_radius_share},
               {"trunk_radius_share_definition", "largest trunk radius over the clearance the parts kept from it (below 1)"},
               {"part_pressure_share", d->smallest_part_pressure_share},
               {"part_pressure_share_definition", "smallest pressure drop across a part, as a share of the root-to-terminal drop"},
               {"unreached_demand_share", d->unreached_share}};
    }
    stats["threshold_relaxations"] = report.threshold_relaxations;
    stats["neighbour_doublings"] = report.neighbour_doublings;
    stats["kamiya_failures"] = report.kamiya_failures;
    stats["hidden_segments"] = report.hidden_segments;
    stats["crowded_segments"] = report.crowded_segments;
    stats["node_optima"] = report.node_optima;
    stats["short_segments"] = report.short_segments;
    stats["short_segments_definition"] = "segments not longer than twice their radius";
    if (!report.short_list.empty()) {
      Json list = Json::array();
      for (const auto& x : report.short_list)
        list.push_back(Json{{"tree", setup_.inlets[std::size_t(x.tree)].id},
                            {"proximal_mm", {x.proximal[0], x.proximal[1], x.proximal[2]}},
                            {"distal_mm", {x.distal[0], x.distal[1], x.distal[2]}},
                            {"length_mm", x.length},
                            {"radius_mm", x.radius}});
      stats["short_segments_left"] = list;
      stats["short_segments_left_why"] =
          "the final check could neither lengthen these (moving either end, or the distal one along or around the vessel, collides or leaves the "
          "domain) nor remove the side branch that merges them with a child (more than 15 % of the terminals)";
    }
    stats["outside_segments"] = report.outside_segments;
    if (setup_.inlets.size() > 1) {
      stats["lenient_connections"] = report.lenient_connections;
      stats["lenient_connections_definition"] =
          "connections whose thickened ancestors were checked only in part: an ancestor that refused 8 connections is then blocked only by vessels "
          "too large to regrow, and after a long run of failures ancestors skip other trees (the exact final check and repair cover both)";
    }
    stats["domain_dimension"] = domain_.dimension();
    stats["domain_measure"] = quantityJson(domain_.measure(), domain_.dimension() == 2 ? "mm^2" : "mm^3");
  }

 private:
  const CcoSetup& setup_;
  GrowthDomain domain_;
  std::vector<CcoInlet> inlets_;  // one per tree, roots in the domain's frame
  std::size_t systems_ = 1;       // kinds of inlet
};

// Pressures of an inlet: [physics] for arteries and other kinds, 5 and 20 mmHg for veins; a vein
// must drain (terminals above the root) and an artery supply.
void readInletPressures(const TomlReader& r, const toml::table& t, const PhysicsParameters& ph, CcoInletSpec& in) {
  const bool vein = in.kind == "vein";
  in.root_pressure = t.get("root_pressure") ? r.quantity(t, "tree.inlet", "root_pressure", Dimension::Pressure)
                     : vein                 ? parseQuantity(kVeinRootPressure, Dimension::Pressure)
                                            : ph.perfusion_pressure;
  in.terminal_pressure = t.get("terminal_pressure") ? r.quantity(t, "tree.inlet", "terminal_pressure", Dimension::Pressure)
                         : vein                     ? parseQuantity(kVeinTerminalPressure, Dimension::Pressure)
                                                    : ph.terminal_pressure;
  checkRange(in.root_pressure, 0, false, Limits::kMaxPressure, false, r.at(t, "root_pressure"), "root_pressure (Pa)");
  checkRange(in.terminal_pressure, 0, false, Limits::kMaxPressure, false, r.at(t, "terminal_pressure"), "terminal_pressure (Pa)");
  const int line = r.lineOf(t.get("root_pressure") ? t.get("root_pressure") : t.get("terminal_pressure") ? t.get("terminal_pressure") : &t);
  if (!(std::abs(in.root_pressure - in.terminal_pressure) >= Limits::kMinPressureDrop))
    throw InputError(r.file(), line, "root_pressure and terminal_pressure of inlet '" + in.id + "' must differ by at least 0.001 Pa");
  if (vein && in.root_pressure > in.terminal_pressure)
    throw InputError(r.file(), line, "inlet '" + in.id + "' is a vein: it drains, so its terminal_pressure must exceed its root_pressure");
  if (in.kind == "artery" && in.root_pressure < in.terminal_pressure)
    throw InputError(r.file(), line, "inlet '" + in.id + "' is an artery: it supplies, so its root_pressure must exceed its terminal_pressure");
}

// [[tree.inlet]]: the trees of the forest, or the one tree of [tree].
void readInlets(const TomlReader& r, const GrowthMethod& m, const toml::table& tree, CcoSetup& s) {
  const auto* list = tree.get("inlet");
  const auto& ph = s.cco.physics;
  if (!list) {
    CcoInletSpec in;
    in.root = readRootOf(r, tree, "tree", s.domain, false);
    in.root_pressure = ph.perfusion_pressure;
    in.terminal_pressure = ph.terminal_pressure;
    in.line = r.lineOf(&tree);
    s.inlets.push_back(in);
    return;
  }
  const auto* arr = list->as_array();
  if (!arr || arr->empty() || !arr->is_array_of_tables())
    throw InputError(r.file(), r.lineOf(list), "inlet must be an array of tables: write each tree as [[tree.inlet]]");
  for (const char* key : {"root_offset", "root", "root_voxel"})
    if (tree.get(key))
      throw InputError(r.file(), r.lineOf(tree.get(key)),
                       std::string("'") + key + "' in [tree] with [[tree.inlet]] tables: give each inlet its root in its table");
  s.inlet_tables = true;
  std::map<std::string, int> per_kind;
  for (const auto& node : *arr) {
    const auto& t = *node.as_table();
    checkMethodKeys(r, m, t, "tree.inlet");
    CcoInletSpec in;
    in.line = r.lineOf(&t);
    in.kind = t.get("kind") ? r.string(t, "tree.inlet", "kind") : "artery";
    if (in.kind.empty() || in.kind.size() > 40 || in.kind.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_-") != std::string::npos)
      throw InputError(r.file(), r.lineOf(t.get("kind")),
                       "kind '" + in.kind + "'; allowed: artery, vein, or a name of 1–40 lower-case letters, digits, '_' and '-'");
    ++per_kind[in.kind];
    in.root = readRootOf(r, t, "tree.inlet", s.domain, arr->size() > 1);
    if (const auto* sh = t.get("share")) {
      if (sh->is_string()) {
        const auto v = r.string(t, "tree.inlet", "share");
        if (v != "territory") throw InputError(r.file(), r.lineOf(sh), "share '" + v + "'; allowed: \"territory\" or a number in (0, 1]");
      } else {
        in.share = r.number(t, "tree.inlet", "share");
        checkRange(in.share, 0, false, 1, true, r.at(t, "share"), "share (of its kind's terminals and flow)");
      }
    }
    s.inlets.push_back(in);
  }
  // Ids: the kind alone when it has one inlet, else kind_1, kind_2, ...; or as the file names them.
  std::map<std::string, int> seen;
  std::set<std::string> ids;
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const auto& t = *(*arr)[i].as_table();
    auto& in = s.inlets[i];
    const int nth = ++seen[in.kind];
    in.id = per_kind[in.kind] == 1 ? in.kind : in.kind + "_" + std::to_string(nth);
    if (t.get("id")) {
      in.id = r.string(t, "tree.inlet", "id");
      if (const auto why = nameProblem(in.id, "id"); !why.empty()) throw InputError(r.file(), r.lineOf(t.get("id")), why);
    }
    if (!ids.insert(in.id).second)
      throw InputError(r.file(), r.lineOf(t.get("id") ? t.get("id") : &t), "a second inlet with id '" + in.id + "'; ids must be unique");
    readInletPressures(r, t, ph, in);
  }
  // Per kind: fixed shares sum to 1, or leave some of the terminals to inlets that win territory.
  for (const auto& [kind, count] : per_kind) {
    double sum = 0;
    bool territory = false;
    int last = 0;
    for (const auto& in : s.inlets)
      if (in.kind == kind) {
        sum += in.share;
        territory |= in.share == 0;
        last = in.line;
        if (in.share > 0 && in.share * double(s.cco.terminals) < 1)
          throw InputError(r.file(), in.line,
                           "inlet '" + in.id + "' has share " + show(in.share) + " of " + std::to_string(s.cco.terminals) +
                               " terminals: less than one terminal; raise its share or the number of terminals");
      }
    if (!territory && std::abs(sum - 1) > 1e-9)
      throw InputError(r.file(), last,
                       "the shares of the " + kind + " inlets sum to " + show(sum) +
                           "; fixed shares of one kind must sum to 1 (or leave one inlet share = \"territory\")");
    if (territory && sum >= 1 - 1e-9)
      throw InputError(
          r.file(), last,
          "the fixed shares of the " + kind + " inlets already sum to " + show(sum) + ", leaving nothing for the inlets that win territory");
  }
  // The capillary bed between arteries and veins needs a pressure drop.
  for (const auto& a : s.inlets)
    for (const auto& v : s.inlets)
      if (a.kind == "artery" && v.kind == "vein" && !(v.terminal_pressure < a.terminal_pressure))
        throw InputError(r.file(), v.line,
                         "vein '" + v.id + "' has terminal_pressure " + show(v.terminal_pressure) + " Pa, not below the " +
                             show(a.terminal_pressure) + " Pa of artery '" + a.id + "': blood would not cross the capillaries from artery to vein");
}

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
  s->domain = readDomainSpec(r, dom, path);

  auto& c = s->cco;
  readSettingsFrom(r, tree, "tree", ccoSettings(), c, s->domain.voxel_mm);
  if (!tree.get("max_closest_neighbours")) c.max_neighbours = c.closest_neighbours;
  checkRules(ccoRules(), c, keysIn(r, tree), Where{file, r.lineOf(&tree)});
  s->terminals_line = r.lineOf(tree.get("terminals"));
  c.physics = readPhysics(r, ccoPhysics(), methodTable(r, m, "physics"));
  c.physics.total_terminals = c.terminals;
  readInlets(r, m, tree, *s);
  readSettingsFrom(r, tree, "tree", ccoDecompositionSettings(), s->decomposition, s->domain.voxel_mm);
  if (s->decomposition.parts > 0 && s->inlet_tables)
    throw InputError(file, r.lineOf(tree.get("parts")), "parts with [[tree.inlet]] tables; allowed: parts for a single tree ([tree] holds its root)");
  return s;
}

}  // namespace

std::vector<std::string> CcoSetup::kinds() const { return kindsOf(inlets); }

Json CcoSetup::describe() const {
  const auto& d = domain;
  const auto& c = cco;
  Json j;
  j["method"] = "cco";
  j["shape"] = domainShapeName(d.shape);
  const auto describeRoot = [&](const RootSpec& root, Json& out) {
    if (d.shape == DomainShape::Mask) {
      if (root.root_in_mm)
        out["root"] = Json{{"value", {root.root_mm.x, root.root_mm.y, root.root_mm.z}}, {"unit", "mm"}};
      else
        out["root_voxel"] = {root.root_voxel.x, root.root_voxel.y, root.root_voxel.z};
    } else {
      out["root_offset"] = root.has_root_offset
                               ? Json{{"value", {root.root_offset_mm.x, root.root_offset_mm.y, root.root_offset_mm.z}}, {"unit", "mm"}}
                               : Json("the top of the domain (+y)");
    }
  };
  if (d.shape == DomainShape::Mask) {
    j["mask"] = d.mask.string();
    j["sampling"] = d.demand_weighted ? "demand" : "uniform";
  } else {
    j[d.shape == DomainShape::Sphere || d.shape == DomainShape::Disc ? "radius" : "side"] = quantityJson(d.size_mm, "mm");
  }
  if (!inlet_tables) describeRoot(inlets.front().root, j);
  if (d.voxel_mm > 0) j["voxel_size"] = quantityJson(d.voxel_mm, "mm");
  j.update(settingsJson(ccoSettings(), c));
  j.update(settingsJson(ccoDecompositionSettings(), decomposition));
  describePhysics(ccoPhysics(), c.physics, c.terminals, j);
  if (inlet_tables) {
    j["terminals_per"] = "kind: each kind of inlet perfuses (or drains) the whole domain with this many terminals";
    Json list = Json::array();
    for (const auto& in : inlets) {
      Json e;
      e["id"] = in.id;
      e["kind"] = in.kind;
      describeRoot(in.root, e);
      e["share"] = in.share > 0 ? Json(in.share) : Json("territory");
      e["root_pressure"] = quantityJson(in.root_pressure, "Pa");
      e["terminal_pressure"] = quantityJson(in.terminal_pressure, "Pa");
      list.push_back(e);
    }
    j["inlets"] = list;
  }
  return j;
}

std::vector<std::filesystem::path> CcoSetup::inputs() const { return domainInputs(domain); }

std::unique_ptr<PreparedGrowth> CcoSetup::prepare(std::uint64_t memory_limit) const {
  return std::make_unique<PreparedCco>(*this, loadDomainSpec(domain, parameter_file, inlets.front().root, memory_limit));
}

// clang-format off
const GrowthMethod kCcoMethod{
    "cco",
    "constrained constructive optimisation (Karch 1999; Kerautret et al., OpenCCO) in a sphere, cube, disc, square or mask: the "
    "domain grows with the tree, each terminal joins the one of its nearest segments whose Kamiya bifurcation gives the "
    "least total volume, no vessel leaves the domain or overlaps another",
    withDomainParams("sphere, cube, disc or square (2D), or mask",
                     "masks: terminals drawn uniformly, or ∝ the mask value (demand)", joinRows({settingRows(ccoSettings()), settingRows(ccoDecompositionSettings()), {
        {"tree.inlet", "id", "text", "its kind (kind_1, kind_2, ... when several)", "the tree's name in graphs and sample.json"},
        {"tree.inlet", "kind", "text", "artery", "artery, vein or a free name; inlets of one kind compete for its `terminals`, each kind fills the domain"},
        {"tree.inlet", "root_offset", "[x, y(, z)] mm", nullptr, "analytic shapes: the root relative to the centre"},
        {"tree.inlet", "root", "[x, y, z] mm", nullptr, "masks: the root in mm in the frame (or root_voxel)"},
        {"tree.inlet", "root_voxel", "[x, y, z] mask voxels", nullptr, "masks: the root in voxels (or root)"},
        {"tree.inlet", "share", "", "territory", "its fixed share (0, 1] of its kind's terminals and flow, or \"territory\": what it wins"},
        {"tree.inlet", "root_pressure", "Pa", "[physics] perfusion_pressure; vein 5 mmHg", "pressure at its root (a vein's outlet)"},
        {"tree.inlet", "terminal_pressure", "Pa", "[physics] terminal_pressure; vein 20 mmHg", "pressure at its terminals (above the root: it drains)"},
    }, settingRows(ccoPhysics())})),
    &readCcoToml};
// clang-format on

}  // namespace angiosynth
