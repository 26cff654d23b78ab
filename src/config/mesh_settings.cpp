#include "config/mesh_settings.hpp"

#include "core/physical_ranges.hpp"
#include "io/mesh_writers.hpp"

namespace angiosynth {

std::string maxAngleProblem(double degrees) {
  if (degrees == 0 || (degrees >= 90 && degrees < 180)) return {};
  return "max_angle = " + show(degrees) + " degrees is out of range; allowed: 0 (none) or [90, 180)";
}

// clang-format off
const std::vector<Setting<MeshParameters>>& meshSettings() {
  static const std::string formats_meaning = "any of " + meshFormatSummary() + ": surface.<format> each";
  static const char* const kFormatsMeaning = formats_meaning.c_str();
  static const std::vector<Setting<MeshParameters>> settings{
      {.table = "mesh", .key = "enabled", .unit = "true/false", .fallback = "true",
       .meaning = "with a [mesh] table: write the vessels' surface (one closed mesh per tree) beside the graphs",
       .field = &MeshParameters::enabled},
      {.table = "mesh", .key = "formats", .unit = "[text]", .fallback = "[\"stl\"]",
       .meaning = kFormatsMeaning,
       .field = &MeshParameters::formats, .choices = meshFormatNames(), .flag = "--format"},
      {.table = "mesh", .key = "method", .unit = "tubes/contour", .fallback = "tubes",
       .meaning = "tubes: each vessel's free middle (no other vessel near its wall) a tube of rings on its exact wall, the parts where vessels "
       "meet (bifurcations, round ends, vessels that touch) contoured and joined to the tubes ring to ring; contour: the whole surface "
       "contoured from the signed distance",
       .field = &MeshParameters::method, .choices = {"tubes", "contour"}, .flag = "--method"},
      {.table = "mesh", .key = "junctions", .unit = "nets/tetrahedra", .fallback = "nets",
       .meaning = "tubes: how the parts where vessels meet are contoured: nets (surface nets, about a third of the triangles: on a uniform "
       "grid where the part's radii are alike, else on the octree, where the result is a closed manifold without "
       "self-intersections and of the union's shape; else marching tetrahedra) or tetrahedra (marching tetrahedra everywhere: "
       "manifold by construction)",
       .field = &MeshParameters::junctions, .choices = {"nets", "tetrahedra"}, .flag = "--junctions"},
      {.table = "mesh", .key = "voxel_size", .unit = "mm", .fallback = "the thinnest vessel's diameter / samples_across",
       .meaning = "the finest grid step",
       .field = &MeshParameters::voxel_mm, .range = {physical::kMinStepMm, physical::kMaxStepMm}, .quantity = Dimension::Length, .flag = "--voxel"},
      {.table = "mesh", .key = "samples_across", .unit = "count", .fallback = "3 (tubes), 4 (contour)",
       .meaning = "grid steps across each vessel's thinnest end where it is contoured (1 … 64); thicker vessels get coarser cells",
       .field = &MeshParameters::samples_across, .range = {1, 64}, .flag = "--samples-across"},
      {.table = "mesh", .key = "ring_spacing", .unit = "radii", .fallback = "8; with capped ends 1.5 times the rings' vertex spacing (turned by half of it)",
       .meaning = "tubes: rings at most this many radii of the vessel apart (0.1 … 100); successive rings are turned by half a vertex spacing",
       .field = &MeshParameters::ring_spacing, .range = {0.1, 100}, .flag = "--ring-spacing"},
      {.table = "mesh", .key = "wall_thickness", .unit = "mm", .fallback = "0 (no wall)",
       .meaning = "a hollow wall of this thickness around each vessel's lumen (Lázaro 2011): the surface bounds the wall (outer side, lumen, a flat "
       "ring at each end, all ends open); one of wall_thickness, wall_ratio, wall_from_graph",
       .field = &MeshParameters::wall_thickness, .range = {0, physical::kMaxRadiusMm}, .quantity = Dimension::Length, .flag = "--wall-thickness"},
      {.table = "mesh", .key = "wall_ratio", .unit = "share of the radius", .fallback = "0 (no wall)",
       .meaning = "a hollow wall of this share of each vessel's radius at each of its ends",
       .field = &MeshParameters::wall_ratio, .range = {0, 100}, .flag = "--wall-ratio"},
      {.table = "mesh", .key = "wall_from_graph", .unit = "true/false", .fallback = "false",
       .meaning = "a hollow wall of each vessel's own thickness (wall values of an [initial] network or a graph file)",
       .field = &MeshParameters::wall_from_graph, .flag = "--wall-from-graph"},
      {.table = "mesh", .key = "uniform", .unit = "true/false", .fallback = "false",
       .meaning = "every vessel at the finest step",
       .field = &MeshParameters::uniform, .flag = "--uniform"},
      {.table = "mesh", .key = "on_surface", .unit = "true/false", .fallback = "false",
       .meaning = "vertices exactly on the surface (no volume restoration)",
       .field = &MeshParameters::on_surface, .flag = "--on-surface"},
      {.table = "mesh", .key = "ends", .unit = "closed/open/capped", .fallback = "closed",
       .meaning = "closed: round vessel ends; open: each tree's inlet and every outlet cut by the plane through its end node, perpendicular to "
       "its vessel (one boundary loop per end); capped: those loops filled by planar caps, faces labelled (CellEntityIds/ModelFaceID "
       "1 the wall, 2 … the caps; surface_faces.csv)",
       .field = &MeshParameters::ends, .choices = {"closed", "open", "capped"}, .flag = "--ends"},
      {.table = "mesh", .key = "decimate", .unit = "true/false", .fallback = "false",
       .meaning = "collapse edges (quadric error, volume kept) while the surface keeps its topology, its triangles do not fold or turn by more than "
       "45 degrees, no new angle falls below 15 degrees (unless one already was), and every moved vertex and new triangle stays within "
       "max_error of the vessels",
       .field = &MeshParameters::decimate, .flag = "--decimate"},
      {.table = "mesh", .key = "max_error", .unit = "share of the local step", .fallback = "0.1",
       .meaning = "with decimate: the largest distance from the vessels' surface, (0, 1]",
       .field = &MeshParameters::max_error, .range = {0, 1, true, false}, .flag = "--max-error"},
      {.table = "mesh", .key = "sliver_angle", .unit = "degrees", .fallback = "10 with capped ends, else 0",
       .meaning = "contoured triangles with an angle below this are repaired (an edge collapsed, a cap's edge flipped, a corner moved) under "
       "decimation's checks, as a tetrahedral mesher needs; so are those with an edge shorter than 0.35 of the local step; 0: none, [0, 30]",
       .field = &MeshParameters::sliver_angle, .range = {0, 30}, .flag = "--sliver-angle"},
      {.table = "mesh", .key = "max_angle", .unit = "degrees", .fallback = "90 with capped ends, else 0",
       .meaning = "with the sliver repair: contoured triangles with an angle above this are improved (the long edge flipped, a corner moved) under "
       "the same checks: a tetrahedral mesher splits the edge an obtuse angle faces; 0: none, else [90, 180)",
       .field = &MeshParameters::max_angle, .range = {0, 180, false, true}, .flag = "--max-angle", .problem = maxAngleProblem},
      {.table = "mesh", .key = "remesh", .unit = "true/false", .fallback = "true with capped ends (without decimate), else false",
       .meaning = "tubes: each contoured part remeshed isotropically to its local step (long edges split, short ones collapsed, flips, moves, "
       "under decimation's checks): the nets' right-angled triangle pairs are what TetGen's quality refinement splits",
       .field = &MeshParameters::remesh, .flag = "--remesh"},
      {.table = "mesh", .key = "flow_extension", .unit = "radii", .fallback = "0",
       .meaning = "open/capped: each end prolonged straight by this many radii of its vessel before the cut (0 … 100); shorter "
                  "where it would come near enough another vessel for the surface to join them (a warning names the end)",
       .field = &MeshParameters::flow_extension, .range = {0, 100}, .flag = "--flow-extension"},
      {.table = "mesh", .key = "clip_box", .unit = "[mm × 6]", .fallback = "none",
       .meaning = "[x0, y0, z0, x1, y1, z1]: the closed surface (closed or capped ends, or a hollow wall) clipped to this box, each side's section "
       "filled flat with a hollow wall's lumens left open (the printed block of Lázaro 2011); ends outside the box are gone",
       .field = &MeshParameters::clip_box, .range = {-physical::kMaxCoordinateMm, physical::kMaxCoordinateMm}, .count = 6, .flag = "--clip-box", .range_unit = "mm"},
  };
  return settings;
}
// clang-format on

// clang-format off
const std::vector<SettingRule<MeshParameters>>& meshRules() {
  using P = MeshParameters;
  static const std::vector<SettingRule<P>> rules{
      {{"formats"}, [](const P& p) { return p.formats.empty() ? std::string("formats must name at least one mesh format") : ""; }},
      {{"wall_thickness", "wall_ratio", "wall_from_graph"},
       [](const P& p) {
         return int(p.wall_thickness > 0) + int(p.wall_ratio > 0) + int(p.wall_from_graph) > 1
                    ? std::string("wall_thickness, wall_ratio and wall_from_graph exclude each other; allowed: one of them")
                    : "";
       }},
      {{"method", "wall_thickness", "wall_ratio", "wall_from_graph"},
       [](const P& p) {
         return p.hollowWall() && p.method != "tubes" ? std::string("a hollow wall is built on the tubes; allowed: method \"tubes\"") : "";
       }},
      {{"ends", "wall_thickness", "wall_ratio", "wall_from_graph"},
       [](const P& p) {
         return p.hollowWall() && p.ends == "capped"
                    ? std::string("a hollow wall keeps its ends open (the lumen runs through); allowed: ends \"open\" or \"closed\"")
                    : "";
       }},
      {{"flow_extension", "ends"},
       [](const P& p) {
         return p.ends == "closed" && p.flow_extension > 0 ? std::string("flow_extension needs open or capped ends; allowed: ends \"open\" or \"capped\"")
                                                           : "";
       }},
      {{"clip_box"},
       [](const P& p) -> std::string {
         if (p.clip_box.empty()) return "";
         for (int k = 0; k < 3; ++k)
           if (!(p.clip_box[std::size_t(k)] < p.clip_box[std::size_t(k + 3)]))
             return "clip_box's lower corner must lie below its upper one on every axis; allowed: x0 < x1, y0 < y1, z0 < z1 (mm)";
         if (p.ends == "open" && !p.hollowWall()) return "clip_box clips a closed surface; allowed: ends \"closed\" or \"capped\", or a hollow wall";
         return "";
       }},
  };
  return rules;
}
// clang-format on

}  // namespace angiosynth
