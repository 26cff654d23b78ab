#include "pipeline/generate_sample.hpp"
#include "pipeline/vascusynth_layout.hpp"
#include "pipeline/mesh_outputs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "angiosynth/version.hpp"
#include "core/error.hpp"
#include "config/sample_settings.hpp"
#include "core/quantity_json.hpp"
#include "core/format.hpp"
#include "domain/growth_domain.hpp"
#include "io/graph_writers.hpp"
#include "io/svg_writer.hpp"
#include "files/text_file.hpp"
#include "pipeline/volume_files.hpp"
#include "pipeline/volume_outputs.hpp"
#include "physics/hemodynamics.hpp"
#include "settings/settings_json.hpp"

namespace angiosynth {
namespace {

using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a) { return std::chrono::duration<double>(Clock::now() - a).count(); }

}  // namespace

Json describeParameters(const Scenario& sc) {
  Json j = sc.growth->describe();
  j["image"] = settingsJson(imageSettings(), sc.image);
  j["image"].update(settingsJson(labelSettings(), sc.image.labels));
  if (sc.curves.enabled) j["curves"] = settingsJson(curveSettings(), sc.curves);
  j["degrade"] = settingsJson(outputSettings(), sc, "degrade");
  j["output"] = settingsJson(outputSettings(), sc, "output");
  if (sc.mesh.enabled) j["mesh"] = settingsJson(meshSettings(), sc.mesh);
  return j;
}

namespace {

// Everything read and checked before growth: domain, profiles, volume sizes, feasibility.
struct PreparedSample {
  std::unique_ptr<PreparedGrowth> growth;
  const DemandMap* map = nullptr;
  std::vector<Profile> profiles;
  VolumeRequest vr;
  bool volumes = false;
};

PreparedSample prepareSample(const SampleRequest& req) {
  const Scenario& sc = *req.scenario;
  PreparedSample ps;
  ps.growth = sc.growth->prepare(req.memory_limit);
  ps.map = &ps.growth->frame();
  const DemandMap& map = *ps.map;

  // The volume request is settled, and its size checked, before the (possibly long) growth.
  ImageParameters ip = sc.image;
  if (req.vascusynth) ip.formats = {"nifti"};  // beside the slices of original_image
  ps.volumes = ip.enabled;
  VolumeRequest& vr = ps.vr;
  std::vector<Profile>& profiles = ps.profiles;
  if (req.profiles)
    profiles = *req.profiles;
  else
    for (const auto& ref : sc.profiles) profiles.push_back(loadProfile(ref, sc.parameter_file, sc.profiles_line));
  for (std::size_t i = 0; i < profiles.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (profiles[i].name == profiles[j].name)
        throw InputError(profiles[i].file, 0, "two profiles are named '" + profiles[i].name + "' (roles image_<name> must differ); rename one file");
  if (ps.volumes) {
    vr.grid = req.vascusynth ? vascusynthGrid(map, req.vascusynth->voxel_mm, "VOXEL_WIDTH", 0) : imageGrid(map, ip, sc.parameter_file, sc.image_line);
    vr.image = ip;
    vr.memory_limit = req.memory_limit;
    vr.parameter_file = sc.parameter_file;
    vr.image_line = sc.image_line;
    vr.vascusynth = req.vascusynth;
    vr.profiles = profiles;
    vr.seed = req.seed;
    vr.sample = req.sample;
    vr.frame = GraphFrame{map.voxel_mm, sc.input_units};
    // Labelled by kind (a dataset's `labels = "kind"`): vessels carry their kind's number and the
    // ignore label comes after the last kind.
    vr.label_numbering.by_kind = !req.class_kinds.empty();
    vr.label_numbering.ignore_value = static_cast<std::uint8_t>(req.class_kinds.empty() ? 2 : req.class_kinds.size() + 1);
    vr.capture = req.capture;
    vr.write_files = req.write_files;
    checkVolumeMemory(vr);
  }
  ps.growth->checkFeasibility();
  return ps;
}

}  // namespace

void checkSampleInputs(const Scenario& sc, std::uint64_t memory_limit) {
  SampleRequest req;
  req.scenario = &sc;
  req.memory_limit = memory_limit;
  prepareSample(req);
}

namespace {

std::string partsNeeded(const std::string& what) {
  return "grows one tree whole; allowed: " + what + " of a tree grown in parts ([tree] parts = K with method \"cco\")";
}

// Growth, class labels and curves: the forest every later stage writes.
Forest growForest(const PreparedSample& ps, const SampleRequest& req, GrowthReport& report, CurveReport& curves, Json& timing) {
  const Scenario& sc = *req.scenario;
  auto t0 = Clock::now();
  Forest forest;
  try {
    ProgressFn progress = req.progress;
    if (req.cancelled)
      progress = [&](std::int64_t done, std::int64_t total) {
        if (req.cancelled()) throw Cancelled();
        if (req.progress) req.progress(done, total);
      };
    if (req.parts_dir) {
      if (ps.growth->parts() == 0) throw InputError(sc.parameter_file, 0, partsNeeded("a join"));
      forest = ps.growth->joinParts(req.seed, req.sample, *req.parts_dir, report, progress);
    } else {
      forest = ps.growth->grow(req.seed, req.sample, report, progress);
    }
    if (!req.class_kinds.empty()) assignClassLabels(forest.trees, req.class_kinds);
    // A sample without a vessel has no truth to label: a method whose parameters leave nothing to
    // grow (a step that leaves the domain, drains that all die) says so instead of writing one.
    const auto& grown = forest.vessels;
    if (std::none_of(grown.parent.begin(), grown.parent.end(), [](std::int32_t p) { return p >= 0; }))
      throw GrowthError("the growth made no vessel: check the method's lengths against the domain (its step, its spacing) and its counts");
  } catch (const GrowthError& e) { throw InputError(sc.parameter_file, 0, e.what()); }
  timing["grow"] = seconds(t0);
  if (sc.curves.enabled) {
    t0 = Clock::now();
    try {
      forest.vessels = curveVessels(forest.vessels, sc.curves, ps.growth->domain(), *ps.map, req.seed, req.sample, curves, req.memory_limit);
    } catch (const InputError& e) { throw InputError(sc.parameter_file, sc.curves_line, e.what()); }
    timing["curves"] = seconds(t0);
  }
  return forest;
}

// GXL (in VascuSynth's dialect when asked) and DOT, and an SVG of a 2-D domain.
void writeGraphs(const Forest& forest, const PreparedSample& ps, const SampleRequest& req, const std::filesystem::path& dir, Json& files) {
  const GraphFrame frame{ps.map->voxel_mm, req.scenario->input_units};
  if (req.vascusynth) return writeVascuSynthGraphs(forest, frame, req.graph_id, dir, files);
  const VascularTree& tree = forest.vessels;
  writeTextFile(dir / "tree.gxl", [&](std::ostream& o) {
    if (req.gxl_dialect == "vascusynth")
      writeVascuSynthGxl(o, tree, frame, req.graph_id);
    else
      writeGxl(o, tree, forest.trees, frame, req.graph_id);
  });
  files["gxl"] = "tree.gxl";
  writeTextFile(dir / "tree.dot", [&](std::ostream& o) { writeDot(o, tree, forest.trees, frame); });
  files["dot"] = "tree.dot";
  const GrowthDomain* domain = ps.growth->domain();
  if (domain && domain->dimension() == 2) {
    writeTextFile(dir / "tree.svg", [&](std::ostream& o) { writeSvg(o, forest, *domain); });
    files["svg"] = "tree.svg";
  }
}

// The surface of each tree ([mesh]), its files and statistics.
std::vector<std::string> writeSurface(const Forest& forest, const SampleRequest& req, const std::filesystem::path& dir, Json& files, Json& stats) {
  std::vector<std::string> kinds;
  for (const auto& t : forest.trees) kinds.push_back(t.kind);
  const auto surface = writeSurfaceFiles(forest.vessels, req.scenario->mesh, req.memory_limit, dir, {}, kinds);
  for (const auto& [format, name] : surface.files.items()) files["surface_" + format] = name;
  stats["surface"] = surface.statistics.toJson();
  return surface.statistics.warnings;
}

// The final tree's size, cost, radii and depths, growth's counts and the method's own.
void addTreeStatistics(const VascularTree& tree, const PreparedSample& ps, const Scenario& sc, const GrowthReport& report,
                       const SampleSummary& summary, Json& stats) {
  const auto& p = sc.growth->physics();
  std::int64_t depth_max = 0;
  double depth_sum = 0, r_min = INFINITY, r_max = 0;
  for (std::int32_t i = 1; i < tree.nodeCount(); ++i) {
    if (tree.isRoot(i)) continue;
    r_min = std::min(r_min, tree.radius[i]);
    r_max = std::max(r_max, tree.radius[i]);
    if (!tree.isTerminal(i)) continue;
    depth_max = std::max<std::int64_t>(depth_max, tree.depth[i]);
    depth_sum += tree.depth[i];
  }
  PhysicsParameters pp = p;
  pp.total_terminals = sc.growth->terminals();
  const double cost = treeCost(tree, pp);
  const double len_unit = sc.input_units.mm_per_length;
  const std::int64_t terminals = summary.terminals;
  stats["terminals"] = terminals;
  stats["nodes"] = tree.nodeCount();
  stats["segments"] = tree.segmentCount();
  stats["total_volume"] = quantityJson(summary.total_volume_mm3, "mm^3");
  stats["cost"] = Json{{"value", cost},
                       {"unit", "mm^" + exactNumber(p.cost_length_exponent + p.cost_radius_exponent)},
                       {"definition", "sum over segments of length^mu * radius^lambda"}};
  stats["cost_" + sc.input_units.length] = Json{{"value", cost / std::pow(len_unit, p.cost_length_exponent + p.cost_radius_exponent)},
                                                {"unit", sc.input_units.length + "^" + exactNumber(p.cost_length_exponent + p.cost_radius_exponent)}};
  stats["depth_max"] = depth_max;
  stats["depth_mean"] = terminals ? depth_sum / double(terminals) : 0.0;
  stats["root_radius"] = quantityJson(report.root_radius_mm, "mm");
  stats["min_radius"] = quantityJson(r_min, "mm");
  stats["max_radius"] = quantityJson(r_max, "mm");
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
  ps.growth->addStatistics(report, stats);
}

Json curveStatistics(const CurveReport& curves) {
  Json j{{"vessels", curves.vessels},
         {"curved", curves.curved},
         {"already_tortuous", curves.already_tortuous},
         {"flattened_by_domain", curves.flattened_by_domain},
         {"flattened_by_overlap", curves.flattened_by_overlap},
         {"left_straight", curves.straightened},
         {"overlap_rounds", curves.overlap_rounds},
         {"overlapping_vessel_pairs", curves.overlapping_vessel_pairs},
         {"nodes_before", curves.nodes_before},
         {"nodes_after", curves.nodes_after},
         {"tortuosity_mean", curves.tortuosity_mean},
         {"tortuosity_min", curves.tortuosity_min},
         {"tortuosity_max", curves.tortuosity_max},
         {"tortuosity_target_error_max", curves.target_error_max},
         {"tortuosity_definition", "distance metric of each vessel (root, bifurcation or terminal to the next): arc length over chord"},
         {"pressures", "radii and flows as grown; pressures along the longer paths (Poiseuille)"}};
  if (curves.target_sum_of_angles)
    j["tortuosity_target"] = "sum of angles per mm (Bullitt et al. 2003), which tortuosity_target_error_max measures against";
  return j;
}

// Mean radius per bifurcation level (the root segment is level 0), as Kerautret et al. (OpenCCO)
// plot it (their Figs. 6–7).
Json radiusByBifurcationLevel(const VascularTree& tree) {
  std::vector<double> sum;
  std::vector<std::int64_t> count;
  for (std::int32_t i = 1; i < tree.nodeCount(); ++i) {
    if (tree.isRoot(i)) continue;
    const auto level = static_cast<std::size_t>(tree.depth[i] - 1);
    if (level >= sum.size()) sum.resize(level + 1, 0.0), count.resize(level + 1, 0);
    sum[level] += tree.radius[i];
    ++count[level];
  }
  Json levels = Json::array();
  for (std::size_t l = 0; l < sum.size(); ++l)
    levels.push_back(Json{{"level", l}, {"segments", count[l]}, {"mean_radius_mm", count[l] ? sum[l] / double(count[l]) : 0.0}});
  return levels;
}

// The trees of the forest: their ids and kinds, roots, flows and pressures.
Json describeTrees(const Forest& forest) {
  const VascularTree& tree = forest.vessels;
  Json trees = Json::array();
  const auto roots = tree.roots();
  for (std::size_t k = 0; k < forest.trees.size(); ++k) {
    const auto& t = forest.trees[k];
    const auto root = roots.at(k);
    const auto seg = tree.child0[root];
    // The pressure at its terminals: that of its first terminal (all are equal in flow-driven trees).
    double terminal_pressure = tree.pressure[root];
    for (std::int32_t i = seg; i >= 0; i = tree.child0[i]) terminal_pressure = tree.pressure[i];
    const Vec3& at = tree.position[root];
    trees.push_back(Json{{"index", k},
                         {"id", t.id},
                         {"kind", t.kind},
                         {"class", t.class_label},
                         {"root_node", root},
                         {"root_position", Json{{"value", {at.x, at.y, at.z}}, {"unit", "mm"}}},
                         {"terminals", seg >= 0 ? tree.terminals[seg] : 0},
                         {"root_radius", quantityJson(seg >= 0 ? tree.startRadius(seg) : 0.0, "mm")},
                         {"flow", quantityJson(seg >= 0 ? tree.flow[seg] : 0.0, "mm^3/s")},
                         {"root_pressure", quantityJson(tree.pressure[root], "Pa")},
                         {"terminal_pressure", quantityJson(terminal_pressure, "Pa")},
                         {"flow_direction", terminal_pressure > tree.pressure[root] ? "terminals to root (drains)" : "root to terminals"}});
  }
  return trees;
}

// The class label of each kind in `classes`.
Json classLegend(const Forest& forest) {
  Json legend = Json::object();
  legend["0"] = "background";
  const auto kinds = kindsByLabel(forest.trees);
  for (std::size_t c = 0; c < kinds.size(); ++c)
    if (!kinds[c].empty()) legend[std::to_string(c + 1)] = kinds[c];
  return legend;
}

}  // namespace

std::filesystem::path SampleSummary::file(const std::string& role) const { return sidecar.at("files").at(role).get<std::string>(); }

bool SampleSummary::wrote(const std::string& role) const { return sidecar.at("files").contains(role); }

PartTaskSummary growSamplePart(const SampleRequest& req, int index, const std::filesystem::path& dir) {
  const Scenario& sc = *req.scenario;
  const PreparedSample ps = prepareSample(req);
  const int parts = ps.growth->parts();
  if (parts == 0) throw InputError(sc.parameter_file, 0, partsNeeded("a task"));
  if (index < 0 || index >= parts)
    throw InputError("--part", 0,
                     std::to_string(index) + " is not a part of the " + std::to_string(parts) + "; allowed: 0 <= I < " + std::to_string(parts));
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string(), 0, "cannot be created (" + ec.message() + "); allowed: a directory this user may write");
  try {
    return ps.growth->growPart(req.seed, req.sample, index, dir);
  } catch (const GrowthError& e) { throw InputError(sc.parameter_file, 0, e.what()); }
}

SampleSummary generateSample(const SampleRequest& req, const std::filesystem::path& dir) {
  const Scenario& sc = *req.scenario;
  Json timing;
  auto t0 = Clock::now();
  const PreparedSample ps = prepareSample(req);
  timing["read_maps"] = seconds(t0);

  GrowthReport report;
  CurveReport curves;
  const Forest forest = growForest(ps, req, report, curves, timing);
  const VascularTree& tree = forest.vessels;

  t0 = Clock::now();
  const auto checkCancelled = [&] {
    if (req.cancelled && req.cancelled()) throw Cancelled();
  };
  checkCancelled();
  if (req.capture) {
    req.capture->forest = forest;
    req.capture->frame = GraphFrame{ps.map->voxel_mm, sc.input_units};
  }
  Json files, stats, degradation;
  if (req.write_files) writeGraphs(forest, ps, req, dir, files);
  timing["write_graphs"] = seconds(t0);
  if (ps.volumes) {
    t0 = Clock::now();
    Json degrade_seconds;
    writeVolumes(forest, ps.vr, dir, files, stats, degradation, &degrade_seconds);
    if (!degrade_seconds.empty()) timing["degrade_effects"] = degrade_seconds;
    timing["rasterize_and_write_volumes"] = seconds(t0);
  } else if (!req.vascusynth && req.write_files) {
    // Without volumes the graphs asked for are written all the same; voxel coordinates in the
    // key points refer to the grid the image would have had.
    t0 = Clock::now();
    writeGraphFiles(tree, forest.trees, imageGrid(*ps.map, sc.image, sc.parameter_file, sc.image_line), sc.image.graph_formats, "", dir, files);
    timing["write_graphs"] = timing["write_graphs"].get<double>() + seconds(t0);
  }
  checkCancelled();
  std::vector<std::string> warnings;
  if (sc.mesh.enabled && req.write_files) {
    t0 = Clock::now();
    warnings = writeSurface(forest, req, dir, files, stats);
    timing["mesh"] = seconds(t0);
  }
  SampleSummary summary;
  summary.warnings = std::move(warnings);
  if (ps.volumes) {
    summary.image_grid = ps.vr.grid;
    summary.image_grid_rule = req.vascusynth ? kVascuSynthGridRule : kImageGridRule;
  }
  summary.terminals = tree.totalTerminals();
  summary.total_volume_mm3 = treeVolume(tree);
  summary.intersecting_pairs = report.intersecting_pairs;
  addTreeStatistics(tree, ps, sc, report, summary, stats);
  if (sc.curves.enabled) stats["curves"] = curveStatistics(curves);
  stats["radius_by_bifurcation_level"] = radiusByBifurcationLevel(tree);

  summary.grow_seconds = timing["grow"].get<double>();
  Json& j = summary.sidecar;
  j["tool"] = Json{{"name", "angiosynth"}, {"version", kVersion}};
  j["command_line"] = req.command_line;
  j["seed"] = req.seed;
  j["sample"] = req.sample;
  j["parameter_file"] = sc.parameter_file;
  j["parameter_format"] = sc.format;
  j["units"] = Json{{"length", "mm"},
                    {"flow", "mm^3/s"},
                    {"pressure", "Pa"},
                    {"viscosity", "Pa*s"},
                    {"input", sc.units_note},
                    {"frame",
                     "positions in mm from the corner of map voxel (0,0,0), axes along the map's x, y, z; "
                     "position_voxel in map voxels"}};
  if (summary.image_grid) {
    const auto& g = *summary.image_grid;
    j["units"]["image_grid"] = Json{{"voxels", g.dims}, {"voxel_size_mm", g.spacing_mm.x}, {"rule", summary.image_grid_rule}};
  }
  j["parameters"] = describeParameters(sc);
  j["trees"] = describeTrees(forest);
  j["classes"] = classLegend(forest);
  for (const auto& [k, v] : req.extra.items()) j["parameters"][k] = v;
  // VascuSynth's layout writes slices and image.nii.gz beside them, whatever [image] formats says.
  if (req.vascusynth && j["parameters"].contains("image") && j["parameters"]["image"].is_object()) {
    j["parameters"]["image"]["formats"] = Json::array({"nifti"});
    j["parameters"]["image"]["slices"] = req.vascusynth->slice_format;
  }
  if (!ps.profiles.empty()) j["degradation"] = degradation;
  j["statistics"] = stats;
  j["files"] = files;
  if (req.record_timing) j["timing_seconds"] = timing;
  if (req.write_files) writeTextFile(dir / "sample.json", [&](std::ostream& o) { o << j.dump(2) << "\n"; });
  return summary;
}

}  // namespace angiosynth
