// `angiosynth rasterize SAMPLE|GRAPH --out STORE.ome.zarr`: a tree's ground truth on any grid,
// written chunk by chunk into an OME-Zarr store (pipeline/chunked_volume.hpp) in memory bounded by
// the chunk. With --task I --tasks N it writes one of N ranges of chunks (a cluster array's task;
// a rerun resumes), and --pyramid --tasks N then builds the coarser levels. Thin: flags, grid, report.
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>

#include <nlohmann/json.hpp>

#include "angiosynth/version.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/vec3.hpp"
#include "core/memory.hpp"
#include "dataset/manifest.hpp"
#include "files/atomic_file.hpp"
#include "files/output_guard.hpp"
#include "io/network_files.hpp"
#include "pipeline/chunked_volume.hpp"
#include "pipeline/volume_outputs.hpp"

namespace angiosynth::cli {
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

// The [image] settings `rasterize` takes as flags; the rest of [image] is about files it does not write.
const std::vector<Setting<ImageParameters>>& rasterizeSettings() {
  static const std::vector<Setting<ImageParameters>> list = [] {
    const std::map<std::string, const char*> flags{{"voxel_size", "--voxel-size"},
                                                   {"supersampling", "--supersampling"},
                                                   {"centerline_connectivity", "--centerline-connectivity"},
                                                   {"background", "--background"},
                                                   {"vessel", "--vessel"},
                                                   {"dtype", "--dtype"},
                                                   {"zarr_chunk", "--chunk"},
                                                   {"zarr_compression", "--compression"},
                                                   {"zarr_levels", "--levels"}};
    std::vector<Setting<ImageParameters>> out;
    for (auto s : imageSettings())
      if (const auto f = flags.find(s.key); f != flags.end()) {
        s.flag = f->second;
        out.push_back(s);
      }
    return out;
  }();
  return list;
}

// The sample's own [image] values for the settings not given on the command line.
void takeSampleSettings(const Json& recorded, const SettingFlagList<ImageParameters>& flags, ImageParameters& p) {
  for (const auto& [setting, option] : flags) {
    if (option->count() > 0 || !recorded.contains(setting->key)) continue;
    const Json& v = recorded[setting->key];
    const std::string key = setting->key;
    if (key == "supersampling" && v.is_number_integer()) p.supersampling = v.get<int>();
    if (key == "centerline_connectivity" && v.is_number_integer()) p.centerline_connectivity = v.get<int>();
    if (key == "background" && v.is_number()) p.background = v.get<double>();
    if (key == "vessel" && v.is_number()) p.vessel = v.get<double>();
    if (key == "dtype" && v.is_string()) p.dtype = v.get<std::string>();
    if (key == "zarr_chunk" && v.is_number_integer()) p.zarr_chunk = v.get<int>();
    if (key == "zarr_compression" && v.is_string()) p.zarr_compression = v.get<std::string>();
    if (key == "zarr_levels" && v.is_number_integer()) p.zarr_levels = v.get<int>();
  }
}

Vec3 vec3Of(const Json& j, const std::string& file, const char* key) {
  const Json& v = j.contains("value") ? j["value"] : j;
  if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
    throw InputError(file, 0, std::string("statistics.") + key + " is not three numbers; allowed: the sample.json angiosynth generate wrote");
  return Vec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
}

// The sample's image grid, or the same field of view at another voxel size.
VolumeGrid sampleGrid(const Json& sample, const fs::path& file, const std::optional<double>& voxel) {
  const Json& st = sample.value("statistics", Json::object());
  if (!st.contains("image_size") || !st.contains("image_voxel_size") || !st.contains("image_origin"))
    throw InputError(file.string(), 0,
                     "records no image grid (statistics.image_size, image_voxel_size, image_origin); allowed: a sample generated with an image, or a "
                     "graph file with --voxel-size");
  const Vec3 n = vec3Of(st["image_size"], file.string(), "image_size");
  VolumeGrid g;
  g.spacing_mm = vec3Of(st["image_voxel_size"], file.string(), "image_voxel_size");
  g.origin_mm = vec3Of(st["image_origin"], file.string(), "image_origin");
  for (int a = 0; a < 3; ++a) g.dims[a] = axisVoxels(n[a], file.string(), 0);
  if (!voxel) return g;
  VolumeGrid f;
  double origin[3];
  for (int a = 0; a < 3; ++a) {
    const double corner = g.origin_mm[a] - g.spacing_mm[a] / 2, extent = g.dims[a] * g.spacing_mm[a];
    f.dims[a] = axisVoxels(std::ceil(extent / *voxel - 1e-9), "--voxel-size", 0);
    origin[a] = corner + *voxel / 2;
  }
  f.spacing_mm = Vec3(*voxel, *voxel, *voxel);
  f.origin_mm = Vec3(origin[0], origin[1], origin[2]);
  return f;
}

// A graph file's grid: its vessels' box, grown by their radius and a voxel.
VolumeGrid graphGrid(const VascularTree& t, double voxel) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    for (int a = 0; a < 3; ++a) {
      const double r = !t.isRoot(i) ? t.maxRadius(i) : 0.0;
      lo[a] = std::min(lo[a], t.position[i][a] - r - voxel);
      hi[a] = std::max(hi[a], t.position[i][a] + r + voxel);
    }
  VolumeGrid g;
  double origin[3];
  for (int a = 0; a < 3; ++a) {
    const double corner = std::floor(lo[a] / voxel) * voxel;
    g.dims[a] = axisVoxels(std::ceil((hi[a] - corner) / voxel - 1e-9), "--voxel-size", 0);
    origin[a] = corner + voxel / 2;
  }
  g.spacing_mm = Vec3(voxel, voxel, voxel);
  g.origin_mm = Vec3(origin[0], origin[1], origin[2]);
  return g;
}

// The node ids of a sample's nodes.csv for the nodes of the tree read from its edges.csv (each
// vessel's id is its distal node's; a root is found by its position), when they number the nodes
// 0 … n − 1: the instance labels are then the ones generate wrote. Empty otherwise.
std::vector<std::int32_t> sampleNodeIds(const ExistingNetwork& net, const fs::path& graph) {
  const fs::path nodes = graph.parent_path() / "nodes.csv";
  if (graph.filename() != "edges.csv" || !fs::exists(nodes)) return {};
  const std::size_t n = std::size_t(net.tree.nodeCount());
  std::vector<std::int32_t> id(n, -1);
  std::vector<char> taken(n, 0);
  const auto take = [&](std::size_t node, long long v) {
    if (v < 0 || v >= (long long)n || taken[std::size_t(v)]) return false;
    id[node] = std::int32_t(v);
    taken[std::size_t(v)] = 1;
    return true;
  };
  std::map<std::array<double, 3>, long long> roots;  // nodes.csv's roots by position
  std::ifstream in(nodes);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    const auto f = csvFieldsOf(line);
    if (f.size() < 5 || f[4] != "root") continue;
    try {
      roots[{std::stod(f[1]), std::stod(f[2]), std::stod(f[3])}] = std::stoll(f[0]);
    } catch (const std::exception&) { return {}; }
  }
  for (std::size_t i = 0; i < n; ++i) {
    long long v = -1;
    if (net.ids[i].empty()) {
      const Vec3& p = net.tree.position[i];
      const auto r = roots.find({p.x, p.y, p.z});
      if (r == roots.end()) return {};
      v = r->second;
    } else {
      std::size_t used = 0;
      try {
        v = std::stoll(net.ids[i], &used);
      } catch (const std::exception&) { return {}; }
      if (used != net.ids[i].size()) return {};
    }
    if (!take(i, v)) return {};
  }
  return id;
}

}  // namespace

CLI::App* addRasterize(CLI::App& app, RasterizeArgs& a) {
  auto* c =
      app.add_subcommand("rasterize",
                         "a tree's ground truth and image on any grid, written chunk by chunk into an OME-Zarr store in memory bounded by "
                         "the chunk (volumes larger than memory); one range of chunks per task for a cluster array, resumable. [image] settings "
                         "not given here are the sample's own");
  c->add_option("INPUT", a.input,
                "a sample directory (its nodes.csv, edges.csv and image grid) or a graph file (.csv, .gxl, .vtp, .swc, .cco; needs --voxel-size)")
      ->required();
  c->add_option("--out", a.out,
                "the store, a new directory (default: <INPUT>.ome.zarr next to the input); an unfinished store of the same job resumes");
  a.flags = addSettingFlags(*c, rasterizeSettings(), a.image);
  c->add_option("--task", a.task, "rasterise only task I of --tasks (0-based; a Slurm array passes $SLURM_ARRAY_TASK_ID)");
  c->add_option("--tasks", a.tasks, "split the chunks into this many contiguous ranges, one per task")->check(CLI::Range(1, 1000000));
  c->add_flag("--pyramid", a.pyramid, "build the coarser levels once all --tasks have finished");
  addCommonOptions(*c, a.common);
  return c;
}

int runRasterize(const RasterizeArgs& a, const std::string& command_line) {
  const auto threads = limitThreads(a.common.threads);
  if (a.task >= 0 && a.tasks == 0) throw InputError("--task", 0, "needs --tasks (how many ranges the chunks are split into)");
  if (a.task >= a.tasks && a.tasks > 0)
    throw InputError("--task", 0, std::to_string(a.task) + " is not below --tasks " + std::to_string(a.tasks) + "; allowed: 0 <= I < N");
  if (a.pyramid && a.task >= 0) throw InputError("--pyramid", 0, "builds the pyramid of all tasks; allowed: --pyramid --tasks N without --task");
  if (a.tasks > 0 && a.task < 0 && !a.pyramid) throw InputError("--tasks", 0, "needs --task I (one range) or --pyramid (after all of them)");
  const fs::path in(a.input);
  const fs::path graph = graphOfInput(a.input);
  const fs::path sample_file = fs::is_directory(in) ? in / "sample.json" : fs::path();
  Json sample;
  if (!sample_file.empty() && fs::exists(sample_file)) {
    try {
      std::ifstream f(sample_file);
      sample = Json::parse(f);
    } catch (const std::exception& e) { throw InputError(sample_file.string(), 0, std::string("is not JSON: ") + e.what()); }
  }
  ImageParameters p = a.image;
  if (sample.contains("parameters") && sample["parameters"].contains("image")) takeSampleSettings(sample["parameters"]["image"], a.flags, p);
  if (!findZarrCodec(p.zarr_compression)) throw InputError("--compression", 0, p.zarr_compression + "; allowed: blosc, zlib");
  fs::path named = fs::absolute(in).lexically_normal();
  if (!named.has_filename()) named = named.parent_path();
  const fs::path out = a.out.empty() ? named.parent_path() / (named.filename().string() + ".ome.zarr") : fs::path(a.out);
  checkOutputPath(out, {in}, "--out");

  const ExistingNetwork net = readNetwork(graph, 1, memoryLimit(a.common));
  Forest forest;
  forest.vessels = net.tree;
  if (const auto ids = sampleNodeIds(net, graph); !ids.empty()) forest.vessels = net.tree.renumbered(ids);
  const auto roots = forest.vessels.roots();
  for (std::size_t t = 0; t < roots.size(); ++t) {
    TreeInfo info;
    info.id = t < net.tree_names.size() && !net.tree_names[t].empty() ? net.tree_names[t] : "tree_" + std::to_string(t);
    info.kind = t < net.tree_kinds.size() && !net.tree_kinds[t].empty() ? net.tree_kinds[t] : "artery";
    forest.trees.push_back(info);
  }
  assignClassLabels(forest.trees);

  if (sample.is_null() && !p.voxel_mm)
    throw InputError("--voxel-size", 0, "is needed for a graph file (a sample directory has its grid); allowed: a voxel edge in mm");
  const VolumeGrid grid = sample.is_null() ? graphGrid(forest.vessels, *p.voxel_mm) : sampleGrid(sample, sample_file, p.voxel_mm);
  ChunkedVolumeOptions o = chunkedVolumeOptions(p, grid, memoryLimit(a.common));
  Json input = {{"graph", fs::absolute(graph).lexically_normal().string()}, {"sha256", sha256File(graph)}};
  if (graph.filename() == "edges.csv" && fs::exists(graph.parent_path() / "nodes.csv"))
    input["nodes_sha256"] = sha256File(graph.parent_path() / "nodes.csv");
  openChunkedVolume(out, o, chunkedJob(o, input));

  const auto& g = o.grid;
  const double voxels = double(g.dims[0]) * g.dims[1] * g.dims[2];
  if (!a.common.quiet)
    std::cerr << "rasterising " << g.dims[0] << " x " << g.dims[1] << " x " << g.dims[2] << " voxels of " << show(g.spacing_mm.x) << " mm ("
              << show(voxels / 1e9, 4) << " Gvoxels) in chunks of " << o.chunk << "^3, " << pyramidLevels(o) << " levels, into " << out.string()
              << "\n";
  Json report = {{"tool", "angiosynth " + std::string(kVersion)}, {"command_line", command_line}};
  const auto write_report = [&](const std::string& name) {
    report["peak_rss_bytes"] = peakRssBytes();
    writeFileAtomically(out / ".angiosynth" / name, report.dump(2) + "\n");
  };
  const auto say = [&](const std::string& what, double seconds, std::int64_t vox) {
    if (!a.common.quiet)
      std::cerr << what << " in " << show(seconds, 4) << " s (" << show(vox / 1e9 / std::max(seconds, 1e-9), 4) << " Gvoxels/s), peak memory "
                << formatBytes(peakRssBytes()) << "\n";
  };
  if (a.pyramid) {
    o.progress = progressPrinter(a.common, "pyramid");
    const PyramidSummary py = buildPyramid(out, o, a.tasks);
    report["pyramid"] = py.toJson();
    write_report("pyramid.json");
    say("built " + std::to_string(py.levels - 1) + " coarser levels (" + counted(py.stored_chunks, "chunk file") + ")", py.seconds,
        std::int64_t(voxels / 7));
    return 0;
  }
  const ChunkTask task = a.tasks > 0 ? ChunkTask{a.task, a.tasks} : ChunkTask{};
  o.progress = progressPrinter(a.common, "rasterising");
  const ChunkedVolumeSummary s = rasterizeChunks(forest, out, o, task);
  report["task"] = {{"index", task.index}, {"count", task.count}};
  report["level0"] = s.toJson();
  say("task " + std::to_string(task.index) + " of " + std::to_string(task.count) + ": " + std::to_string(s.task_chunks) + " chunks (" +
          std::to_string(s.occupied_chunks) + " reached by vessels, " + std::to_string(s.resumed_chunks) + " done before), " +
          formatBytes(s.stored_bytes) + " stored",
      s.seconds, std::int64_t(voxels * double(s.task_chunks) / double(std::max<std::int64_t>(1, s.chunks))));
  if (a.tasks == 0) {
    o.progress = progressPrinter(a.common, "pyramid");
    const PyramidSummary py = buildPyramid(out, o, 1);
    report["pyramid"] = py.toJson();
    say("built " + std::to_string(py.levels - 1) + " coarser levels", py.seconds, std::int64_t(voxels / 7));
  }
  write_report("task-" + std::to_string(task.index) + "-of-" + std::to_string(task.count) + ".json");
  return 0;
}

}  // namespace angiosynth::cli
