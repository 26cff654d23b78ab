// `angiosynth mesh SAMPLE_DIR|GRAPH_FILE`: the outer surface of a tree angiosynth grew (or of any
// graph file it reads) as a closed triangle mesh per tree (src/mesh). Thin: options, files, report.
#include <chrono>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "angiosynth/version.hpp"
#include "commands.hpp"
#include "setting_flags.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/physical_ranges.hpp"
#include "io/mesh_writers.hpp"
#include "io/network_files.hpp"
#include "files/staged_directory.hpp"
#include "pipeline/mesh_outputs.hpp"

namespace angiosynth::cli {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

CLI::App* addMesh(CLI::App& app, MeshArgs& a) {
  auto* c = app.add_subcommand("mesh",
                               "the outer surface of a tree as a closed triangle mesh per tree (in the formats of --format), "
                               "from a sample directory angiosynth generate wrote or a graph file");
  c->add_option("INPUT", a.input, "a sample directory (its nodes.csv and edges.csv are read) or a graph file: .csv, .gxl, .vtp, .swc, .cco")
      ->required();
  c->add_option("--out", a.out, "output directory (default: <INPUT>_mesh next to the input)");
  addSettingFlags(*c, meshSettings(), a.mesh);
  c->add_flag("--force", a.force, "replace an earlier angiosynth output in --out (only the files it wrote there)");
  addCommonOptions(*c, a.common);
  return c;
}

int runMesh(const MeshArgs& a, const std::string& command_line) {
  const auto threads = limitThreads(a.common.threads);
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path in(a.input);
  const fs::path graph = graphOfInput(a.input);
  const auto net = readNetwork(graph, 1, memoryLimit(a.common));
  refuseLargeJunctions(net, graph.string(), "mesh takes");
  // By default beside the input, named after it: never inside it, whatever the path ends with
  // ("sample/", "sample/.", ".").
  fs::path named = fs::absolute(in).lexically_normal();
  if (!named.has_filename()) named = named.parent_path();
  const fs::path out = a.out.empty() ? named.parent_path() / (named.filename().string() + "_mesh") : fs::path(a.out);
  StagedDirectory dir(out, a.force ? ExistingOutput::ReplaceOwn : ExistingOutput::Refuse, {in});
  MeshParameters p = a.mesh;
  if (p.formats.empty()) p.formats = {"stl"};
  // The rules between settings, as for a [mesh] table (flags name no line).
  checkRules(meshRules(), p, [](const char*) { return std::optional<Where>(); });
  const auto surface = writeSurfaceFiles(net.tree, p, memoryLimit(a.common), dir.path(), progressPrinter(a.common, "meshing"), {}, net.ids);
  Json j = {{"tool", "angiosynth " + std::string(kVersion)},
            {"command_line", command_line},
            {"input", graph.string()},
            {"parameters", surface.parameters},
            {"statistics", surface.statistics.toJson()},
            {"files", surface.files},
            {"timing_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  std::ofstream(dir.path() / "mesh.json") << j.dump(2) << '\n';
  dir.commit();
  const auto& s = surface.statistics;
  if (!a.common.quiet)
    std::cerr << "wrote " << dir.target().string() << ": " << s.triangles << " triangles (" << counted(s.trees, "tree") << ", "
              << counted(s.segments, "segment") << ", finest step " << show(s.finest_step_mm) << " mm), enclosed volume "
              << show(s.topology.volume_mm3) << " mm^3\n";
  // Also with --quiet: a surface not as asked is wrong for what comes next.
  printWarnings(s.warnings, (dir.target() / "mesh.json").string() + " (warnings)");
  return 0;
}

}  // namespace angiosynth::cli
