// Method "vascusynth": its parameters, TOML reader, description and grow function.
#include <cmath>

#include "core/error.hpp"
#include "core/quantity_json.hpp"
#include "grow/common/feasibility.hpp"
#include "grow/common/method_tables.hpp"
#include "grow/vascusynth/setup.hpp"
#include "settings/input_paths.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;

// [tree]'s settings.
// clang-format off
const std::vector<Setting<GrowthOptions>>& vascuSynthSettings() {
  using O = GrowthOptions;
  static const std::vector<Setting<O>> settings{
      {.table = "tree", .key = "terminals", .unit = "count", .fallback = nullptr, .meaning = "N, the number of terminal segments",
       .field = &O::terminals, .range = {1, Limits::kMaxTerminals}},
      {.table = "tree", .key = "min_distance", .unit = "mm", .fallback = "1 voxel", .meaning = "candidates closer than this to any vessel are drawn again",
       .field = &O::min_distance_mm, .range = {0, Limits::kMaxLength}, .quantity = Dimension::Length, .fallback_is_value = true},
      {.table = "tree", .key = "closest_neighbours", .unit = "count", .fallback = "5", .meaning = "segments tried per candidate terminal",
       .field = &O::closest_neighbours, .range = {1, Limits::kMaxNeighbours}, .fallback_is_value = true},
      {.table = "tree", .key = "min_segment_length", .unit = "mm", .fallback = "0.05 voxel", .meaning = "no segment shorter than this",
       .field = &O::min_segment_length_mm, .range = {0, Limits::kMaxLength, true, false}, .quantity = Dimension::Length},
      {.table = "tree", .key = "min_length_ratio", .unit = "ratio", .fallback = "2",
       .meaning = "no segment shorter than this × its radius (CCO's l > 2r; 0: VascuSynth's rule, which leaves stubs where bifurcations merge)",
       .field = &O::min_length_ratio, .range = {0, 100}, .fallback_is_value = true},
      {.table = "tree", .key = "relax_sweeps", .unit = "count", .fallback = "4",
       .meaning = "final sweeps that move every bifurcation to its cost optimum for the final radii, keeping every constraint (0: the greedy tree as grown)",
       .field = &O::relax_sweeps, .range = {0, 100}, .fallback_is_value = true},
      {.table = "tree", .key = "avoid_intersections", .unit = "true/false", .fallback = "true", .meaning = "refuse connections whose vessels would overlap",
       .field = &O::avoid_intersections},
      {.table = "tree", .key = "rules", .unit = "angiosynth/vascusynth", .fallback = "angiosynth",
       .meaning = "vascusynth: VascuSynth's own constraints, to reproduce its trees (min_length_ratio 0, relax_sweeps 0, avoid_intersections "
       "false; those keys are then not given); the bifurcation search stays this program's exact-cost one from the midpoint",
       .field = &O::rules, .choices = {"angiosynth", "vascusynth"}},
  };
  return settings;
}
// clang-format on

// VascuSynth's files carry every physical value: none has a default but the exponents.
// clang-format off
const std::vector<Setting<PhysicsParameters>>& vascuSynthPhysics() {
  static const std::vector<Setting<PhysicsParameters>> settings{
      physicsSetting("murray_exponent", "3"),        physicsSetting("murray_band_edges", "none"), physicsSetting("murray_band_exponents", "none"),
      physicsSetting("cost_radius_exponent", "2"), physicsSetting("cost_length_exponent", "1"),
      physicsSetting("viscosity", nullptr),          physicsSetting("perfusion_pressure", nullptr), physicsSetting("terminal_pressure", nullptr),
      physicsSetting("perfusion_flow", nullptr)};
  return settings;
}
// clang-format on

class PreparedVascuSynth final : public PreparedGrowth {
 public:
  PreparedVascuSynth(const VascuSynthSetup& s, DemandMap map) : setup_(s), map_(std::move(map)) {}
  const DemandMap& frame() const override { return map_; }
  void checkFeasibility() const override {
    std::int64_t inside = 0;  // voxels of non-zero demand
    for (float v : map_.demand) inside += v > 0;
    const double measure = double(inside) * map_.voxel_mm * map_.voxel_mm * map_.voxel_mm;
    const auto& g = setup_.growth;
    const std::string& file = setup_.domain.parameter_file;
    checkPacking(g.terminals, g.min_distance_mm, measure, file, setup_.terminals_line);
    checkVesselRoom(g.physics, g.terminals, measure, 3, file, setup_.terminals_line);
  }
  Forest grow(std::uint64_t seed, std::uint64_t sample, GrowthReport& report, const ProgressFn& progress) const override {
    GrowthOptions opt = setup_.growth;
    opt.root_mm = map_.toMm(setup_.domain.root_voxel);
    opt.seed = seed;
    opt.sample = sample;
    return singleTreeForest(growVascuSynth(map_, opt, report, progress));
  }
  void addStatistics(const GrowthReport& report, Json& stats) const override {
    stats["relaxed_bifurcations"] = report.relaxed_bifurcations;
    if (!(setup_.growth.min_length_ratio > 0)) return;
    stats["short_segments"] = report.short_segments;
    stats["short_segments_definition"] = "segments shorter than min_length_ratio times their radius";
  }

 private:
  const VascuSynthSetup& setup_;
  DemandMap map_;
};

std::shared_ptr<const GrowthSetup> readVascuSynthToml(const TomlReader& r, const GrowthMethod& m) {
  auto s = std::make_shared<VascuSynthSetup>();
  const std::string file = r.file();
  const std::filesystem::path path = file;
  const auto& dom = methodTable(r, m, "domain");
  const auto& tree = methodTable(r, m, "tree");
  BoxMapSpec& d = s->domain;
  d.parameter_file = file;
  auto& g = s->growth;
  d.voxel_mm = r.quantity(dom, "domain", "voxel_size", Dimension::Length);
  checkRange(d.voxel_mm, Limits::kMinVoxel, false, Limits::kMaxVoxel, false, r.at(dom, "voxel_size"), "voxel_size (mm)");
  d.demand_map = resolveInputPath(r.string(dom, "domain", "demand_map"), path, r.lineOf(dom.get("demand_map")));
  if (dom.get("supply_map") && dom.get("supply_coefficients"))
    throw InputError(file, r.lineOf(dom.get("supply_coefficients")), "give supply_map or supply_coefficients, not both");
  if (dom.get("supply_map")) {
    d.supply_map = resolveInputPath(r.string(dom, "domain", "supply_map"), path, r.lineOf(dom.get("supply_map")));
    d.supply_line = r.lineOf(dom.get("supply_map"));
  } else if (const auto* c = dom.get("supply_coefficients")) {
    d.supply_coefficients = r.numbers(c, "supply_coefficients", 0);
    if (d.supply_coefficients.back() < 0 || d.supply_coefficients.back() > Limits::kMaxSupplyCutoff)
      throw InputError(file, r.lineOf(c), "supply_coefficients: the last value is the cut-off radius (map voxels); allowed: 0 to 1e6");
  }

  if (const auto mm = readRoot(r, tree, d.root_voxel, d.root_line, "map voxels", "")) d.root_voxel = *mm / d.voxel_mm;
  readSettingsFrom(r, tree, "tree", vascuSynthSettings(), g, d.voxel_mm);
  if (g.rules == "vascusynth") {
    for (const char* fixed : {"min_length_ratio", "relax_sweeps", "avoid_intersections"})
      if (const auto* given = tree.get(fixed))
        throw InputError(
            file, r.lineOf(given),
            std::string(fixed) + " is set by rules = \"vascusynth\" (VascuSynth's own value); allowed: leave it out, or rules = \"angiosynth\"");
    g.useVascuSynthRules();
  }
  if (!g.min_segment_length_mm) g.min_segment_length_mm = g.minSegmentLength(d.voxel_mm);
  s->terminals_line = r.lineOf(tree.get("terminals"));
  g.physics = readPhysics(r, vascuSynthPhysics(), methodTable(r, m, "physics"));
  g.physics.total_terminals = g.terminals;
  return s;
}

}  // namespace

Json VascuSynthSetup::describe() const {
  const auto& g = growth;
  const auto& p = g.physics;
  const auto& d = domain;
  Json j;
  j["method"] = "vascusynth";
  j["demand_map"] = d.demand_map.string();
  if (d.supply_map.empty())
    j["supply_coefficients"] = d.supply_coefficients;
  else
    j["supply_map"] = d.supply_map.string();
  j["voxel_size"] = quantityJson(d.voxel_mm, "mm");
  j["root"] = Json{{"value", {d.root_voxel.x * d.voxel_mm, d.root_voxel.y * d.voxel_mm, d.root_voxel.z * d.voxel_mm}}, {"unit", "mm"}};
  j["root_voxel"] = {d.root_voxel.x, d.root_voxel.y, d.root_voxel.z};
  j.update(settingsJson(vascuSynthSettings(), g));
  describePhysics(vascuSynthPhysics(), p, g.terminals, j);
  return j;
}

std::vector<std::filesystem::path> VascuSynthSetup::inputs() const {
  std::vector<std::filesystem::path> in{domain.demand_map};
  if (!domain.supply_map.empty()) in.push_back(domain.supply_map);
  return in;
}

std::unique_ptr<PreparedGrowth> VascuSynthSetup::prepare(std::uint64_t memory_limit) const {
  return std::make_unique<PreparedVascuSynth>(*this, loadDomain(domain, memory_limit));
}

// clang-format off
const GrowthMethod kVascuSynthMethod{
    "vascusynth",
    "VascuSynth's oxygen-demand CCO (Hamarneh & Jassi 2010) on box maps: terminals drawn ∝ the remaining demand, each joined to the "
    "cheapest of its nearest segments for the cost Σ l^μ r^λ, radii by Poiseuille flow and Murray's law",
    joinRows({{
        {"domain", "demand_map", "file", nullptr, "the oxygen-demand box map (VascuSynth format), beside the parameter file or the working directory"},
        {"domain", "supply_map", "file", "none", "the supply box map; without it supply_coefficients hold everywhere"},
        {"domain", "supply_coefficients", "numbers", "[0.65, 0.34, 0.01, 7]", "supply reduction coefficients, the last one the cut-off radius in map voxels"},
        {"domain", "voxel_size", "mm", nullptr, "the edge of a map voxel"},
        {"tree", "root_voxel", "[x, y, z] map voxels", nullptr, "the perforation point (or root in mm; one of the two)"},
        {"tree", "root", "[x, y, z] mm", nullptr, "the perforation point in mm from the map's corner (or root_voxel)"},
    }, settingRows(vascuSynthSettings()), settingRows(vascuSynthPhysics())}),
    &readVascuSynthToml};
// clang-format on

}  // namespace angiosynth
