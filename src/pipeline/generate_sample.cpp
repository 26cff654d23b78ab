#include "pipeline/generate_sample.hpp"

#include <chrono>
#include <cmath>
#include <numbers>

#include "angiosynth/version.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "grow/cco_grower.hpp"
#include "io/graph_writers.hpp"
#include "io/growth_domain_files.hpp"
#include "io/svg_writer.hpp"
#include "io/map_files.hpp"
#include "io/param_checks.hpp"
#include "io/text_file.hpp"
#include "pipeline/volume_outputs.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); }

Json q(double v, const char* unit) { return Json{{"value", v}, {"unit", unit}}; }

}  // namespace

Json describeParameters(const Scenario& sc) {
  const auto& g = sc.growth;
  const auto& p = g.physics;
  Json j;
  j["method"] = sc.method;
  if (sc.method == "cco") {
    const auto& d = sc.cco_domain;
    const auto& c = sc.cco;
    j["shape"] = domainShapeName(d.shape);
    if (d.shape == DomainShape::Mask) {
      j["mask"] = d.mask.string();
      j["sampling"] = d.demand_weighted ? "demand" : "uniform";
      if (d.root_in_mm) j["root"] = Json{{"value", {d.root_mm.x, d.root_mm.y, d.root_mm.z}}, {"unit", "mm"}};
      else j["root_voxel"] = {sc.root_voxel.x, sc.root_voxel.y, sc.root_voxel.z};
    } else {
      j[d.shape == DomainShape::Sphere || d.shape == DomainShape::Disc ? "radius" : "side"] = q(d.size_mm, "mm");
      j["root_offset"] = d.has_root_offset ? Json{{"value", {d.root_offset_mm.x, d.root_offset_mm.y, d.root_offset_mm.z}}, {"unit", "mm"}}
                                           : Json("the top of the domain (+y)");
    }
    if (sc.voxel_mm > 0) j["voxel_size"] = q(sc.voxel_mm, "mm");
    j["terminals"] = g.terminals;
    j["closest_neighbours"] = c.closest_neighbours;
    j["max_closest_neighbours"] = c.max_neighbours;
    j["kamiya_iterations"] = c.kamiya_iterations;
    j["kamiya_tolerance"] = c.kamiya_tolerance;
    j["draws_before_relaxing"] = c.draws_before_relaxing;
    j["relaxation"] = c.relaxation;
  } else {
    j["demand_map"] = sc.demand_map.string();
    if (sc.supply_map.empty()) j["supply_coefficients"] = sc.supply_coefficients;
    else j["supply_map"] = sc.supply_map.string();
    j["voxel_size"] = q(sc.voxel_mm, "mm");
    j["root"] = Json{{"value", {sc.root_voxel.x * sc.voxel_mm, sc.root_voxel.y * sc.voxel_mm, sc.root_voxel.z * sc.voxel_mm}},
                     {"unit", "mm"}};
    j["root_voxel"] = {sc.root_voxel.x, sc.root_voxel.y, sc.root_voxel.z};
    j["terminals"] = g.terminals;
    j["min_distance"] = q(g.min_distance_mm, "mm");
    j["closest_neighbours"] = g.closest_neighbours;
    j["min_segment_length"] = q(g.minSegmentLength(sc.voxel_mm), "mm");
    j["avoid_intersections"] = g.avoid_intersections;
  }
  j["murray_exponent"] = p.murray_exponent;
  if (sc.method != "cco") {
    j["cost_radius_exponent"] = p.cost_radius_exponent;
    j["cost_length_exponent"] = p.cost_length_exponent;
  }
  j["viscosity"] = q(p.viscosity, "Pa*s");
  j["perfusion_pressure"] = q(p.perfusion_pressure, "Pa");
  j["terminal_pressure"] = q(p.terminal_pressure, "Pa");
  j["perfusion_flow"] = q(p.perfusion_flow, "mm^3/s");
  j["terminal_flow"] = q(p.perfusion_flow / double(g.terminals), "mm^3/s");
  const auto& im = sc.image;
  j["image"] = Json{{"enabled", im.enabled},
                    {"voxel_size", q(im.voxel_mm > 0 ? im.voxel_mm : sc.voxel_mm, "mm")},
                    {"field_of_view", im.field_of_view_mm.x > 0 ? Json{{"value", {im.field_of_view_mm.x, im.field_of_view_mm.y, im.field_of_view_mm.z}}, {"unit", "mm"}}
                                                               : Json("the demand map's extent")},
                    {"supersampling", im.supersampling},
                    {"background", im.background},
                    {"vessel", im.vessel},
                    {"dtype", im.dtype},
                    {"formats", im.formats},
                    {"graph_formats", im.graph_formats}};
  j["profiles"] = sc.profiles;
  return j;
}

namespace {

// Everything read and checked before growth: domain, profiles, volume sizes, feasibility.
struct PreparedSample {
  std::optional<DemandMap> owned_map;
  std::optional<GrowthDomain> domain;
  const DemandMap* map = nullptr;
  std::vector<Profile> profiles;
  VolumeRequest vr;
  bool volumes = false;
};

// Estimated radii of an N-terminal tree: a symmetric tree whose segments halve in flow and
// shrink by 2^(-1/γ) in radius and 2^(-1/d) in length per level, with the given pressure drop.
// It sits within 15 % of grown CCO trees' root and terminal radii (examples/cco_sphere_3d.toml:
// 1.44 vs 1.25 mm, 0.091 vs 0.090 mm).
struct RadiusEstimate {
  double root = 0, terminal = 0, spacing = 0;
};

RadiusEstimate estimateRadii(const PhysicsParameters& p, std::int64_t terminals, double measure, int dim) {
  const double n = double(terminals), levels = std::log2(std::max(1.0, n));
  const double root_length = std::pow(measure, 1.0 / dim) / 2;
  double path = 0;  // Σ over levels of 2^-k · 2^(-k/d) · 2^(4k/γ)
  for (int k = 0; k <= int(levels); ++k)
    path += std::pow(2.0, -k - double(k) / dim + 4.0 * k / p.murray_exponent);
  const double dp = p.perfusion_pressure - p.terminal_pressure;
  RadiusEstimate e;
  e.root = std::pow(8 * p.viscosity * p.perfusion_flow * root_length * path / (std::numbers::pi * dp), 0.25);
  e.terminal = e.root * std::pow(n, -1.0 / p.murray_exponent);
  e.spacing = std::pow(measure / n, 1.0 / dim);
  return e;
}

// Fails in milliseconds, naming the cause, where growth could only grind: more terminals than fit
// at the minimum distance, or vessels too thick for the room each terminal has.
void checkFeasibility(const Scenario& sc, const PreparedSample& ps) {
  const bool cco = sc.method == "cco";
  const DemandMap& m = *ps.map;
  std::int64_t inside = 0;  // voxels of the domain (non-zero demand)
  for (float v : m.demand) inside += v > 0;
  const double measure = cco ? ps.domain->measure() : double(inside) * m.voxel_mm * m.voxel_mm * m.voxel_mm;
  const int dim = cco ? ps.domain->dimension() : 3;
  const auto& g = sc.growth;
  const std::int64_t n = cco ? sc.cco.terminals : g.terminals;
  const std::string unit = dim == 2 ? " mm^2" : " mm^3";
  if (!cco && g.min_distance_mm > 0) {
    // Balls of diameter min_distance around the terminals cannot fill more than 74 % of space.
    const double ball = std::numbers::pi / 6 * std::pow(g.min_distance_mm, 3);
    const double capacity = 0.74 * measure / ball;
    if (double(n) > capacity)
      throw InputError(sc.parameter_file, sc.terminals_line,
                       std::to_string(n) + " terminals cannot lie " + show(g.min_distance_mm) + " mm apart in the " +
                           show(measure) + unit + " of non-zero demand: at most about " +
                           std::to_string(std::int64_t(capacity)) +
                           " fit (sphere packing); use fewer terminals, a smaller minimum distance, or a larger domain");
  }
  if (cco) {
    // A terminal per voxel of the domain at most: finer than its resolution the mask says nothing.
    if (n > inside)
      throw InputError(sc.parameter_file, sc.terminals_line,
                       std::to_string(n) + " terminals exceed the " + std::to_string(inside) +
                           " voxels of the domain; use fewer terminals or a finer voxel_size (mask)");
  }
  const RadiusEstimate e = estimateRadii(cco ? sc.cco.physics : g.physics, n, measure, dim);
  // Terminal vessels wider than a quarter of the spacing between terminals leave no room to
  // branch without collisions: measured on the shipped examples, growth slows 25-fold at 0.42 of
  // that limit (100x their flow) and runs for minutes past it (300x), while 1x sits at 0.13.
  if (2 * e.terminal > e.spacing / 4)
    throw InputError(sc.parameter_file, sc.terminals_line,
                     "vessels too thick for the domain: this flow, pressure drop and viscosity give terminal vessels of "
                     "diameter about " + show(2 * e.terminal) + " mm (root radius about " + show(e.root) + " mm), but " +
                         std::to_string(n) + " terminals in " + show(measure) + unit + " lie about " + show(e.spacing) +
                         " mm apart, and growth needs diameters below a quarter of that; lower perfusion_flow or viscosity, raise the pressure drop, or use "
                         "fewer terminals (vessel radius scales with flow^(1/4))");
}

PreparedSample prepareSample(const SampleRequest& req) {
  const Scenario& sc = *req.scenario;
  PreparedSample ps;
  const bool cco = sc.method == "cco";
  if (cco) ps.domain.emplace(loadGrowthDomain(sc, req.memory_limit));
  ps.map = cco ? &ps.domain->frame() : &ps.owned_map.emplace(loadDomain(sc, req.memory_limit));
  const DemandMap& map = *ps.map;

  // The volume request is settled, and its size checked, before the (possibly long) growth.
  ImageParameters ip = sc.image;
  if (!req.formats.empty()) ip.formats = req.formats;
  if (req.vascusynth_layout) ip.formats = {"nifti"};  // beside the PNG slices of original_image
  ps.volumes = ip.enabled && !req.no_image;
  VolumeRequest& vr = ps.vr;
  std::vector<Profile>& profiles = ps.profiles;
  if (req.profiles) profiles = *req.profiles;
  else
    for (const auto& ref : sc.profiles) profiles.push_back(loadProfile(ref, sc.parameter_file, sc.profiles_line));
  for (std::size_t i = 0; i < profiles.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (profiles[i].name == profiles[j].name)
        throw InputError(profiles[i].file, 0, "two profiles are named '" + profiles[i].name +
                                                  "' (roles image_<name> must differ); rename one file");
  if (ps.volumes) {
    vr.grid = req.vascusynth_layout ? vascusynthGrid(map, req.output_voxel_mm, "VOXEL_WIDTH", 0)
                                     : imageGrid(map, ip, sc.parameter_file, sc.image_line);
    vr.image = ip;
    vr.memory_limit = req.memory_limit;
    vr.parameter_file = sc.parameter_file;
    vr.image_line = sc.image_line;
    vr.slices = req.vascusynth_layout;
    vr.profiles = profiles;
    vr.seed = req.seed;
    vr.sample = req.sample;
    vr.frame = GraphFrame{map.voxel_mm, sc.input_units};
    vr.vascusynth_noise_layout = req.vascusynth_noise_layout;
    checkVolumeMemory(vr);
  }
  checkFeasibility(sc, ps);
  return ps;
}

}  // namespace

void checkSampleInputs(const Scenario& sc, std::uint64_t memory_limit) {
  SampleRequest req;
  req.scenario = &sc;
  req.memory_limit = memory_limit;
  req.no_image = !sc.image.enabled;
  prepareSample(req);
}

Json generateSample(const SampleRequest& req, const std::filesystem::path& dir) {
  const Scenario& sc = *req.scenario;
  Json timing;
  auto t0 = Clock::now();
  const bool cco = sc.method == "cco";
  PreparedSample ps = prepareSample(req);
  std::optional<GrowthDomain>& domain = ps.domain;
  const DemandMap& map = *ps.map;
  const VolumeRequest& vr = ps.vr;
  const bool volumes = ps.volumes;
  const std::vector<Profile>& profiles = ps.profiles;
  timing["read_maps"] = seconds(t0);

  GrowthOptions opt = sc.growth;
  opt.root_mm = cco ? ccoRoot(sc, *domain) : map.toMm(sc.root_voxel);
  opt.seed = req.seed;
  opt.sample = req.sample;
  GrowthReport report;
  t0 = Clock::now();
  VascularTree tree;
  try {
    if (cco) {
      CcoOptions co = sc.cco;
      co.root_mm = opt.root_mm;
      co.seed = req.seed;
      co.sample = req.sample;
      tree = growCco(*domain, co, report, req.progress);
    } else {
      tree = growVascuSynth(map, opt, report, req.progress);
    }
  } catch (const GrowthError& e) {
    throw InputError(sc.parameter_file, 0, e.what());
  }
  timing["grow"] = seconds(t0);

  t0 = Clock::now();
  GraphFrame frame{map.voxel_mm, sc.input_units};
  Json files;
  if (req.vascusynth_layout) {
    writeTextFile(dir / "tree_structure.xml", [&](std::ostream& o) { writeVascuSynthGxl(o, tree, frame, req.graph_id); });
    files["gxl"] = "tree_structure.xml";
  } else {
    writeTextFile(dir / "tree.gxl", [&](std::ostream& o) {
      if (req.gxl_dialect == "vascusynth") writeVascuSynthGxl(o, tree, frame, req.graph_id);
      else writeGxl(o, tree, frame, req.graph_id);
    });
    files["gxl"] = "tree.gxl";
    writeTextFile(dir / "tree.dot", [&](std::ostream& o) { writeDot(o, tree, frame); });
    files["dot"] = "tree.dot";
    if (cco && domain->dimension() == 2) {
      writeTextFile(dir / "tree.svg", [&](std::ostream& o) { writeSvg(o, tree, *domain); });
      files["svg"] = "tree.svg";
    }
  }
  timing["write_graphs"] = seconds(t0);

  Json stats, degradation;
  if (volumes) {
    t0 = Clock::now();
    Json degrade_seconds;
    writeVolumes(tree, vr, dir, files, stats, degradation, &degrade_seconds);
    if (!degrade_seconds.empty()) timing["degrade_effects"] = degrade_seconds;
    timing["rasterize_and_write_volumes"] = seconds(t0);
  }

  // Statistics of the final tree.
  const auto& p = opt.physics;
  std::int64_t depth_max = 0;
  double depth_sum = 0, r_min = INFINITY, r_max = 0;
  for (std::int32_t i = 1; i < tree.nodeCount(); ++i) {
    r_min = std::min(r_min, tree.radius[i]);
    r_max = std::max(r_max, tree.radius[i]);
    if (!tree.isTerminal(i)) continue;
    depth_max = std::max<std::int64_t>(depth_max, tree.depth[i]);
    depth_sum += tree.depth[i];
  }
  PhysicsParameters pp = p;
  pp.total_terminals = opt.terminals;
  const double cost = treeCost(tree, pp);
  const double len_unit = sc.input_units.mm_per_length;
  stats["terminals"] = tree.terminalCount();
  stats["nodes"] = tree.nodeCount();
  stats["segments"] = tree.segmentCount();
  stats["total_volume"] = q(treeVolume(tree), "mm^3");
  stats["cost"] = Json{{"value", cost},
                       {"unit", "mm^" + exactNumber(p.cost_length_exponent + p.cost_radius_exponent)},
                       {"definition", "sum over segments of length^mu * radius^lambda"}};
  stats["cost_" + sc.input_units.length] =
      Json{{"value", cost / std::pow(len_unit, p.cost_length_exponent + p.cost_radius_exponent)},
           {"unit", sc.input_units.length + "^" + exactNumber(p.cost_length_exponent + p.cost_radius_exponent)}};
  stats["depth_max"] = depth_max;
  stats["depth_mean"] = tree.terminalCount() ? depth_sum / double(tree.terminalCount()) : 0.0;
  stats["root_radius"] = q(report.root_radius_mm, "mm");
  stats["min_radius"] = q(r_min, "mm");
  stats["max_radius"] = q(r_max, "mm");
  stats["intersecting_pairs"] = report.intersecting_pairs;
  stats["intersecting_pairs_definition"] = "segment capsules that overlap and are more than two segments apart";
  stats["candidates_drawn"] = report.candidates;
  stats["rejected_too_close"] = report.rejected_too_close;
  stats["rejected_unreachable"] = report.rejected_unreachable;
  stats["rejected_intersection"] = report.rejected_intersection;
  stats["repair_rounds"] = report.repair_rounds;
  stats["retracted_terminals"] = report.retracted_terminals;
  stats["moved_nodes"] = report.moved_nodes;
  stats["repaired_terminals"] = report.repaired_terminals;
  if (cco) {
    stats["threshold_relaxations"] = report.threshold_relaxations;
    stats["neighbour_doublings"] = report.neighbour_doublings;
    stats["kamiya_failures"] = report.kamiya_failures;
    stats["short_segments"] = report.short_segments;
    stats["short_segments_definition"] = "segments not longer than twice their radius";
    stats["outside_segments"] = report.outside_segments;
    stats["domain_dimension"] = domain->dimension();
    stats["domain_measure"] = q(domain->measure(), domain->dimension() == 2 ? "mm^2" : "mm^3");
  }
  // Mean radius per bifurcation level (the root segment is level 0), as in seed 000 Fig. 6–7.
  {
    std::vector<double> sum;
    std::vector<std::int64_t> count;
    for (std::int32_t i = 1; i < tree.nodeCount(); ++i) {
      const auto level = static_cast<std::size_t>(tree.depth[i] - 1);
      if (level >= sum.size()) sum.resize(level + 1, 0.0), count.resize(level + 1, 0);
      sum[level] += tree.radius[i];
      ++count[level];
    }
    Json levels = Json::array();
    for (std::size_t l = 0; l < sum.size(); ++l)
      levels.push_back(Json{{"level", l}, {"segments", count[l]}, {"mean_radius_mm", count[l] ? sum[l] / double(count[l]) : 0.0}});
    stats["radius_by_bifurcation_level"] = levels;
  }

  Json j;
  j["tool"] = Json{{"name", "angiosynth"}, {"version", kVersion}};
  j["command_line"] = req.command_line;
  j["seed"] = req.seed;
  j["sample"] = req.sample;
  j["parameter_file"] = sc.parameter_file;
  j["parameter_format"] = sc.format;
  j["units"] = Json{{"length", "mm"}, {"flow", "mm^3/s"}, {"pressure", "Pa"}, {"viscosity", "Pa*s"},
                    {"input", sc.units_note},
                    {"frame", "positions in mm from the corner of map voxel (0,0,0), axes along the map's x, y, z; "
                              "position_voxel in map voxels"}};
  j["parameters"] = describeParameters(sc);
  for (const auto& [k, v] : req.extra.items()) j["parameters"][k] = v;
  if (!profiles.empty()) j["degradation"] = degradation;
  j["statistics"] = stats;
  j["files"] = files;
  if (req.record_timing) j["timing_seconds"] = timing;
  writeTextFile(dir / "sample.json", [&](std::ostream& o) { o << j.dump(2) << "\n"; });
  return j;
}

}  // namespace angiosynth
