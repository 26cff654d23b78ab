// `angiosynth mesh SAMPLE_DIR|GRAPH_FILE`: the outer surface of a tree angiosynth grew (or of any
// graph file it reads) as a closed triangle mesh per tree (src/mesh). Thin: options, files, report.
#include <chrono>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "angiosynth/version.hpp"
#include "commands.hpp"
#include "core/error.hpp"
#include "core/physical_ranges.hpp"
#include "io/mesh_writers.hpp"
#include "io/network_files.hpp"
#include "files/staged_directory.hpp"
#include "pipeline/mesh_outputs.hpp"

namespace angiosynth::cli {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

CLI::App* addMesh(CLI::App& app, MeshArgs& a) {
  auto* c = app.add_subcommand("mesh", "the outer surface of a tree as a closed triangle mesh per tree (STL, OBJ, PLY, OFF, VTP), "
                                       "from a sample directory angiosynth generate wrote or a graph file");
  c->add_option("INPUT", a.input, "a sample directory (its nodes.csv and edges.csv are read) or a graph file: .csv, .gxl, .vtp, .swc, .cco")
      ->required();
  c->add_option("--out", a.out, "output directory (default: <INPUT>_mesh next to the input)");
  c->add_option("--method", a.method,
                "tubes: each vessel's free middle a tube of rings on its wall, the parts where vessels meet contoured and joined to "
                "them (default); contour: the whole surface contoured from the signed distance")
      ->check(CLI::IsMember({"tubes", "contour"}));
  c->add_option("--junctions", a.junctions,
                "tubes: contour the parts where vessels meet by surface nets where they pass their checks (closed, manifold, no "
                "self-intersection, the union's shape; about a third of the triangles), else by marching tetrahedra (nets, the "
                "default); or by marching tetrahedra only (tetrahedra)")
      ->check(CLI::IsMember({"nets", "tetrahedra"}));
  c->add_option("--ring-spacing", a.ring_spacing, "tubes: rings at most this many radii apart, aligned (default 8; with --ends capped 1.5 times the rings' vertex spacing, "
                                          "about 0.9 radii at 3 samples across, turned by half of it, which TetGen's -q1.414 leaves unsplit)")->check(finiteIn(0.1, 100));
  c->add_option("--wall-thickness", a.wall_thickness,
                "a hollow wall of this thickness in mm around each vessel's lumen (seed 004): the wall's surface, outer side, lumen "
                "and a flat ring at each open end")
      ->check(finiteIn(0, physical::kMaxRadiusMm));
  c->add_option("--wall-ratio", a.wall_ratio, "a hollow wall of this share of each vessel's radius")->check(finiteIn(0, 100));
  c->add_flag("--wall-from-graph", a.wall_from_graph, "a hollow wall of each vessel's own thickness (the graph file's wall values)");
  c->add_option("--voxel", a.voxel_mm, "finest grid step in mm (default: the thinnest vessel's diameter / --samples-across)")
      ->check(finiteIn(0, physical::kMaxStepMm));
  c->add_option("--samples-across", a.samples_across,
                "grid steps across each vessel's thinnest end where it is contoured: each vessel is sampled at the coarsest step (the "
                "finest times a power of 2) that keeps this many (default 3 with --method tubes, 4 with contour)")
      ->check(CLI::Range(1, 64));
  c->add_flag("--uniform", a.uniform, "sample every vessel at the finest step (no adaptive resolution)");
  c->add_flag("--on-surface", a.on_surface,
              "keep every vertex exactly on the vessels' surface (default: vertices move by a fraction of the chords' sagitta so the "
              "enclosed volume is the vessels')");
  c->add_option("--ends", a.ends,
                "closed: round vessel ends (default); open: each tree's inlet and every outlet cut by the plane through its end node, "
                "perpendicular to its vessel; capped: planar caps on those cuts, faces labelled (CellEntityIds/ModelFaceID in VTP, "
                "`face` in PLY, groups in OBJ; surface_faces.csv)")
      ->check(CLI::IsMember({"closed", "open", "capped"}));
  c->add_option("--flow-extension", a.flow_extension, "with --ends open or capped: prolong each end straight by this many radii (default 0)")
      ->check(finiteIn(0, 100));
  c->add_flag("--decimate", a.decimate,
              "collapse edges (quadric error) while the surface stays within --max-error of the vessels, its topology and its "
              "triangles' shape (no flips, no new angle below 15 degrees unless it was already)");
  c->add_option("--max-error", a.max_error, "with --decimate: largest distance of a moved vertex or a new triangle's centroid from the "
                                             "vessels' surface, as a share of the local grid step (default 0.1)")
      ->check(finiteIn(0, 1));
  c->add_option("--sliver-angle", a.sliver_angle,
                "repair contoured triangles with an angle below this many degrees (collapse, flip or move under the checks of "
                "--decimate), as TetGen needs; 0: none (default 10 with --ends capped, else 0)")
      ->check(finiteIn(0, 30));
  c->add_option("--max-angle", a.max_angle,
                "with the sliver repair: improve contoured triangles with an angle above this many degrees (Delaunay flip or a corner "
                "moved, under the same checks): TetGen splits every edge an obtuse angle faces; 0: none, else 90 ... 180 (default 90 "
                "with --ends capped, else 0)")
      ->check(finiteIn(0, 180));
  c->add_option("--remesh", a.remesh,
                "1: remesh each contoured part isotropically to its local step (edges split, collapsed, flipped, vertices moved, under "
                "the checks of --decimate), so TetGen's quality refinement leaves the surface whole; 0: not (default 1 with --ends capped "
                "and without --decimate, else 0)")
      ->check(CLI::IsMember({0, 1}));
  c->add_option("--clip-box", a.clip_box,
                "X0,Y0,Z0,X1,Y1,Z1: clip the closed surface to this box (mm), each side's section filled flat (a hollow wall's lumen "
                "stays open there: the printed block of seed 004)")
      ->delimiter(',')
      ->expected(6);
  c->add_option("--format", a.formats, "mesh formats (default stl): " + meshFormatSummary())
      ->delimiter(',')
      ->check(CLI::IsMember(meshFormatNames()));
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
  const auto net = readNetwork(graph, 1, memoryLimit(a.common));
  refuseLargeJunctions(net, graph.string(), "mesh takes");
  // By default beside the input, named after it: never inside it, whatever the path ends with
  // ("sample/", "sample/.", ".").
  fs::path named = fs::absolute(in).lexically_normal();
  if (!named.has_filename()) named = named.parent_path();
  const fs::path out = a.out.empty() ? named.parent_path() / (named.filename().string() + "_mesh") : fs::path(a.out);
  StagedDirectory dir(out, a.force ? ExistingOutput::ReplaceOwn : ExistingOutput::Refuse, {in});
  MeshParameters p;
  p.method = a.method;
  p.ring_spacing = a.ring_spacing;
  p.junctions = a.junctions;
  p.wall_thickness = a.wall_thickness;
  p.wall_ratio = a.wall_ratio;
  p.wall_from_graph = a.wall_from_graph;
  if (int(p.wall_thickness > 0) + int(p.wall_ratio > 0) + int(p.wall_from_graph) > 1)
    throw InputError("", 0, "--wall-thickness, --wall-ratio and --wall-from-graph exclude each other; allowed: one of them");
  if (p.hollowWall() && a.method != "tubes")
    throw InputError("", 0, "a hollow wall is built on the tubes; allowed: --method tubes");
  if (p.hollowWall() && a.ends == "capped")
    throw InputError("", 0, "a hollow wall keeps its ends open (the lumen runs through); allowed: --ends open (or closed, which opens them)");
  if (a.voxel_mm > 0 && a.voxel_mm < physical::kMinStepMm)
    throw InputError("", 0, "--voxel " + show(a.voxel_mm) + " mm is out of range; allowed: " + show(physical::kMinStepMm) + " to " +
                                show(physical::kMaxStepMm) + " mm (0: the default)");
  p.voxel_mm = a.voxel_mm;
  p.samples_across = a.samples_across;
  p.uniform = a.uniform;
  p.on_surface = a.on_surface;
  p.ends = a.ends;
  p.flow_extension = a.flow_extension;
  p.decimate = a.decimate;
  p.max_error = a.max_error;
  p.sliver_angle = a.sliver_angle;
  p.max_angle = a.max_angle;
  p.remesh = a.remesh;
  if (p.max_angle >= 0)  // given
    if (const auto why = maxAngleProblem(p.max_angle); !why.empty()) throw InputError("", 0, "--max-angle: " + why);
  if (p.ends == "closed" && p.flow_extension > 0) throw InputError("", 0, "--flow-extension needs --ends open or capped");
  p.clip_box = a.clip_box;
  if (const auto why = clipBoxProblem(p); !why.empty()) throw InputError("", 0, why);
  if (!a.formats.empty()) p.formats = a.formats;
  const auto surface = writeSurfaceFiles(net.tree, p, memoryLimit(a.common), dir.path(), progressPrinter(a.common, "meshing"), {}, net.ids);
  Json j = {{"tool", "angiosynth " + std::string(kVersion)},
            {"command_line", command_line},
            {"input", graph.string()},
            {"parameters", surface.parameters},
            {"statistics", surface.statistics},
            {"files", surface.files},
            {"timing_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  std::ofstream(dir.path() / "mesh.json") << j.dump(2) << '\n';
  dir.commit();
  if (!a.common.quiet)
    std::cerr << "wrote " << dir.target().string() << ": " << surface.statistics["triangles"] << " triangles (" << surface.statistics["trees"]
              << " trees, " << surface.statistics["segments"] << " segments, finest step " << surface.statistics["finest_step_mm"]
              << " mm), enclosed volume " << surface.statistics["enclosed_volume_mm3"] << " mm^3\n";
  return 0;
}

}  // namespace angiosynth::cli
