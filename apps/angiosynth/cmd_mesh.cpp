// `angiosynth mesh SAMPLE_DIR|GRAPH_FILE`: the outer surface of a tree angiosynth grew (or of any
// graph file it reads) as a closed triangle mesh per tree (src/mesh). Thin: options, files, report.
#include <chrono>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "angiosynth/version.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "io/mesh_writers.hpp"
#include "io/network_files.hpp"
#include "io/staged_directory.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth::cli {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

CLI::App* addMesh(CLI::App& app, MeshArgs& a) {
  auto* c = app.add_subcommand("mesh", "the outer surface of a tree as a closed triangle mesh per tree (STL, OBJ, PLY, OFF, VTP), "
                                       "from a sample directory angiosynth generate wrote or a graph file");
  c->add_option("INPUT", a.input, "a sample directory (its nodes.csv and edges.csv are read) or a graph file: .csv, .gxl, .vtp, .swc, .cco")
      ->required();
  c->add_option("--out", a.out, "output directory (default: <INPUT>_mesh next to the input)");
  c->add_option("--voxel", a.voxel_mm, "finest grid step in mm (default: the thinnest vessel's diameter / --samples-across)")
      ->check(finiteIn(0, 1e6));
  c->add_option("--samples-across", a.samples_across,
                "grid steps across each vessel's thinnest end: each vessel is sampled at the coarsest step (the finest times a power of 2) "
                "that keeps this many (default 4)")
      ->check(CLI::Range(1, 64));
  c->add_flag("--uniform", a.uniform, "sample every vessel at the finest step (no adaptive resolution)");
  c->add_flag("--on-surface", a.on_surface,
              "keep every vertex exactly on the vessels' surface (default: vertices move by a fraction of the chords' sagitta so the "
              "enclosed volume is the vessels')");
  c->add_option("--format", a.formats, "mesh formats: stl (binary), obj, ply (binary), off, vtp (default stl)")
      ->delimiter(',')
      ->check(CLI::IsMember({"stl", "obj", "ply", "off", "vtp"}));
  c->add_flag("--force", a.force, "replace an earlier angiosynth output in --out (only the files it wrote there)");
  addCommonOptions(*c, a.common);
  return c;
}

int runMesh(const MeshArgs& a, const std::string& command_line) {
  const auto threads = limitThreads(a.common.threads);
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path in(a.input);
  if (!fs::exists(in)) throw InputError(a.input, 0, "no such sample directory or graph file");
  const fs::path graph = fs::is_directory(in) ? in / "edges.csv" : in;
  if (!fs::exists(graph)) throw InputError(graph.string(), 0, "no such file: a sample directory holds the nodes.csv and edges.csv angiosynth generate writes");
  const auto net = readNetwork(graph);
  const fs::path out = a.out.empty() ? fs::path(in.lexically_normal().string() + "_mesh") : fs::path(a.out);
  StagedDirectory dir(out, a.force ? ExistingOutput::ReplaceOwn : ExistingOutput::Refuse, {in});
  SurfaceOptions o;
  o.voxel_mm = a.voxel_mm;
  o.samples_across = a.samples_across;
  o.adaptive = !a.uniform;
  o.restore_volume = !a.on_surface;
  o.memory_limit = memoryLimit(a.common);
  SurfaceReport report;
  const auto mesh = vesselSurface(net.tree, o, &report, progressPrinter(a.common, "meshing"));
  const auto topo = meshTopology(mesh);
  const std::vector<std::string> formats = a.formats.empty() ? std::vector<std::string>{"stl"} : a.formats;
  Json files = Json::object();
  for (const auto& f : formats) {
    const std::string name = "surface." + f;
    std::ofstream os(dir.path() / name, std::ios::binary);
    meshWriter(f)(os, mesh);
    if (!os) throw std::runtime_error("cannot write " + (dir.path() / name).string());
    files[f] = name;
  }
  std::int64_t trees = 0, segments = 0;
  for (std::int32_t i = 0; i < net.tree.nodeCount(); ++i) trees += net.tree.isRoot(i), segments += !net.tree.isRoot(i) && !net.tree.isLink(i);
  Json j = {{"tool", "angiosynth " + std::string(kVersion)},
            {"command_line", command_line},
            {"input", graph.string()},
            {"parameters", {{"voxel_mm", a.voxel_mm > 0 ? Json(a.voxel_mm) : Json(nullptr)}, {"samples_across", a.samples_across}, {"adaptive", !a.uniform}, {"volume_restored", !a.on_surface}}},
            {"method", "marching tetrahedra of the signed distance to the union of each tree's capsules and round cones, on a 2:1-balanced "
                       "octree of cells sized to each vessel's radius, split into conforming tetrahedra"},
            {"statistics",
             {{"trees", trees},
              {"segments", segments},
              {"vertices", mesh.vertices.size()},
              {"triangles", mesh.triangles.size()},
              {"triangles_per_segment", segments > 0 ? double(mesh.triangles.size()) / double(segments) : 0.0},
              {"finest_step_mm", report.voxel_mm},
              {"coarsest_cell_mm", report.coarsest_mm},
              {"levels", report.levels},
              {"cells", report.cells},
              {"largest_volume_move_mm", report.largest_volume_move_mm},
              {"estimated_bytes", report.estimated_bytes},
              {"enclosed_volume_mm3", topo.volume_mm3},
              {"boundary_edges", topo.boundary_edges},
              {"nonmanifold_edges", topo.nonmanifold_edges},
              {"misoriented_edges", topo.misoriented_edges},
              {"degenerate_triangles", topo.degenerate_triangles},
              {"cavities_removed", report.cavities_removed},
              {"tree_components", topo.tree_components},
              {"tree_euler_characteristic", topo.tree_euler}}},
            {"files", files},
            {"timing_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  std::ofstream(dir.path() / "mesh.json") << j.dump(2) << '\n';
  dir.commit();
  if (!a.common.quiet)
    std::cerr << "wrote " << dir.target().string() << ": " << mesh.triangles.size() << " triangles (" << trees << " trees, "
              << segments << " segments, step " << report.voxel_mm << " mm), enclosed volume " << topo.volume_mm3 << " mm^3\n";
  return 0;
}

}  // namespace angiosynth::cli
