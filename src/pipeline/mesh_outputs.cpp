#include "pipeline/mesh_outputs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "core/error.hpp"
#include "io/mesh_writers.hpp"
#include "core/format.hpp"
#include "mesh/box_clip.hpp"
#include "mesh/decimate.hpp"
#include "mesh/hollow_wall.hpp"
#include "mesh/tube_surface.hpp"
#include "mesh/vessel_ends.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth {

using Json = nlohmann::ordered_json;

namespace {

// surface_faces.csv: one row per face label (the wall, then each end), as the ids the VTP and
// PLY files carry (ModelFaceID = CellEntityIds = face + 1).
// With a clip box, an end outside it is `outside_box`, and each side of the box has a row (kind
// `box`, end its side, the section's area).
void writeFaces(std::ostream& os, const std::vector<VesselEnd>& ends, const EndCutReport& cut, const std::string& mode,
                const std::vector<std::string>& kinds, const std::vector<std::string>& vessel_ids, const std::vector<double>& box,
                const BoxClipReport& clipped) {
  os << "face_id,kind,tree,vessel,end,state,centre_x,centre_y,centre_z,normal_x,normal_y,normal_z,radius,cap_area,loop_vertices\n";
  os << "1,wall,,,,,,,,,,,,,\n";
  std::vector<char> closed(ends.size(), 0);
  for (auto e : cut.left_closed) closed[std::size_t(e)] = 1;
  const auto outside = [&](const Vec3& c) {
    return !box.empty() && (c.x < box[0] || c.y < box[1] || c.z < box[2] || c.x > box[3] || c.y > box[4] || c.z > box[5]);
  };
  for (std::size_t k = 0; k < ends.size(); ++k) {
    const auto& e = ends[k];
    const bool vein = std::size_t(e.tree) < kinds.size() && kinds[std::size_t(e.tree)] == "vein";
    os << k + 2 << ',' << ((e.root != vein) ? "inlet" : "outlet") << ',' << e.tree << ','
       << (std::size_t(e.vessel) < vessel_ids.size() ? vessel_ids[std::size_t(e.vessel)] : std::to_string(e.vessel)) << ',' << (e.root ? "root" : "leaf") << ','
       << (outside(e.centre) ? "outside_box" : closed[k] ? "left_closed" : mode) << ',' << exactNumber(e.centre.x) << ',' << exactNumber(e.centre.y) << ',' << exactNumber(e.centre.z) << ','
       << exactNumber(e.normal.x) << ',' << exactNumber(e.normal.y) << ',' << exactNumber(e.normal.z) << ',' << exactNumber(e.radius) << ','
       << exactNumber(cut.cap_area_mm2[k]) << ',' << cut.loop_vertices[k] << '\n';
  }
  if (box.empty()) return;
  for (int side = 0; side < 6; ++side) {
    const int axis = side / 2;
    const double sign = side % 2 ? 1 : -1;
    double c[3] = {(box[0] + box[3]) / 2, (box[1] + box[4]) / 2, (box[2] + box[5]) / 2};
    c[axis] = box[std::size_t(axis + (side % 2 ? 3 : 0))];
    double n[3] = {0, 0, 0};
    n[axis] = sign;
    os << ends.size() + 2 + std::size_t(side) << ",box,,," << kBoxSideNames[side] << ",section";
    for (double v : c) os << ',' << exactNumber(v);
    for (double v : n) os << ',' << exactNumber(v);
    os << ",," << exactNumber(clipped.section_area_mm2[std::size_t(side)]) << ",\n";
  }
}

// The area of each end's face (labels 1 … n), and optionally the vertices of its loops (the
// edges its triangles use once).
std::vector<double> endFaceAreas(const SurfaceMesh& m, std::size_t n, std::vector<std::int32_t>* loop_vertices = nullptr) {
  std::vector<double> area(n, 0.0);
  std::vector<std::array<std::int32_t, 3>> edges;  // (face, lower vertex, higher vertex)
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    const auto f = m.triangle_face[k];
    if (f <= 0 || std::size_t(f) > n) continue;
    const auto& t = m.triangles[k];
    area[std::size_t(f - 1)] += triangleArea(m, t);
    for (int i = 0; i < 3; ++i) edges.push_back({f, std::min(t[std::size_t(i)], t[std::size_t((i + 1) % 3)]), std::max(t[std::size_t(i)], t[std::size_t((i + 1) % 3)])});
  }
  if (loop_vertices) {
    loop_vertices->assign(n, 0);
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i + 1;
      while (j < edges.size() && edges[j] == edges[i]) ++j;
      if (j - i == 1) ++(*loop_vertices)[std::size_t(edges[i][0] - 1)];
      i = j;
    }
  }
  return area;
}

}  // namespace

SurfaceFiles writeSurfaceFiles(const VascularTree& tree, const MeshParameters& p, std::uint64_t memory_limit, const std::filesystem::path& dir,
                               const std::function<void(std::int64_t, std::int64_t)>& progress, const std::vector<std::string>& tree_kinds,
                               const std::vector<std::string>& vessel_ids) {
  const bool tubes = p.method == "tubes";
  // At least two grid steps across the thinnest vessel: coarser, its surface falls between the
  // samples and comes out empty, or its volume wrong by a tenth and more.
  if (p.voxel_mm) {
    double thinnest = INFINITY;
    for (std::int32_t i = 0; i < tree.nodeCount(); ++i)
      if (!tree.isRoot(i) && !tree.isLink(i)) thinnest = std::min({thinnest, tree.radius[i], tree.startRadius(i)});
    if (*p.voxel_mm > thinnest)
      throw InputError("", 0, "a mesh voxel of " + exactNumber(*p.voxel_mm) + " mm is coarser than half the thinnest vessel's diameter (" +
                                  exactNumber(2 * thinnest) + " mm); allowed: at most " + exactNumber(thinnest) + " mm, two steps across it");
  }
  WallThickness wall;
  wall.constant_mm = p.wall_thickness;
  wall.ratio = p.wall_ratio;
  wall.from_tree = p.wall_from_graph;
  const bool walls = wall.any();
  SurfaceOptions o;
  o.voxel_mm = p.voxel_mm.value_or(0);
  o.samples_across = p.samples_across.value_or(tubes ? 3 : 4);
  o.adaptive = !p.uniform;
  o.restore_volume = !p.on_surface;
  o.memory_limit = memory_limit;
  SurfaceReport report;
  const bool cut_ends = p.ends != "closed" || walls;  // a hollow wall's ends are open
  const auto ends = cut_ends ? openEnds(tree, p.flow_extension) : std::vector<VesselEnd>{};
  EndCutReport cut;
  DecimateReport reduced, slivers;
  DecimateOptions d;
  d.max_error = p.max_error;
  d.sliver_deg = p.sliverAngle();
  d.obtuse_deg = p.maxAngle();
  TubeSurfaceReport tube_report;
  HollowWallReport wall_report;
  SurfaceMesh mesh;
  // The tubes' options, for the tube surface and a hollow wall's two (whose ends are open).
  TubeSurfaceOptions to;
  to.junction = o;
  to.ring_spacing_radii = p.ringSpacing();
  to.ends = ends;
  to.cap_ends = !walls && p.ends == "capped";
  to.decimate = p.decimate;
  to.decimation = d;
  to.nets = p.junctions == "nets";
  to.remesh = p.remeshes();
  if (walls) {
    mesh = hollowWall(tree, to, wall, &wall_report, progress);
    tube_report = wall_report.outer;
    report.voxel_mm = std::min(wall_report.outer.finest_step_mm, wall_report.lumen.finest_step_mm);
    report.estimated_bytes = std::max(wall_report.outer.estimated_bytes, wall_report.lumen.estimated_bytes);
    cut.cut = wall_report.rings;
    cut.left_closed = wall_report.not_joined;
    // A ring's loop vertices: its two loops' together.
    cut.cap_area_mm2 = endFaceAreas(mesh, ends.size(), &cut.loop_vertices);
  } else if (tubes) {
    mesh = tubeSurface(tree, to, &tube_report, progress);
    cut = tube_report.ends;
    report.voxel_mm = tube_report.finest_step_mm;
    report.estimated_bytes = tube_report.estimated_bytes;
    reduced.before = tube_report.triangles_before_decimation + tube_report.tube_triangles;
    reduced.collapses = tube_report.decimation_collapses;
    reduced.largest_error_mm = tube_report.decimation_largest_error_mm;
  } else {
    o.finish = [&](SurfaceMesh& m, const std::function<double(std::int32_t, const Vec3&)>& distance) {
      // Slivers before the cut too (tube_surface.cpp says why).
      if (d.sliver_deg > 0) slivers = repairSlivers(m, d, distance);
      if (cut_ends) cut = cutEnds(m, ends, p.ends == "capped");
      if (p.decimate) reduced = decimate(m, d, distance);
      else if (d.sliver_deg > 0) slivers += repairSlivers(m, d, distance, nullptr, true);
    };
    mesh = vesselSurface(cut_ends ? prolongEnds(tree, ends) : tree, o, &report, progress);
  }
  // The caps as made: the sliver repair may join two of a cap's loop vertices.
  if (p.ends == "capped" && !walls) cut.cap_area_mm2 = endFaceAreas(mesh, ends.size(), &cut.loop_vertices);
  BoxClipReport clipped;
  if (!p.clip_box.empty()) {
    const auto& b = p.clip_box;
    clipped = clipToBox(mesh, Vec3(b[0], b[1], b[2]), Vec3(b[3], b[4], b[5]), std::int32_t(ends.size()) + 1);
    // What is left of each end's face (a box side may cut it; outside the box it is gone).
    if (cut_ends) cut.cap_area_mm2 = endFaceAreas(mesh, ends.size());
  }
  if (mesh.triangles.empty() && p.clip_box.empty())
    throw std::logic_error("the surface of a tree with vessels came out empty");
  const auto topo = meshTopology(mesh);
  SurfaceFiles out;
  out.files = Json::object();
  if (cut_ends || !p.clip_box.empty()) {
    std::ofstream os(dir / "surface_faces.csv", std::ios::binary);
    writeFaces(os, ends, cut, walls ? "open" : p.ends, tree_kinds, vessel_ids, p.clip_box, clipped);
    if (!os) throw std::runtime_error("cannot write " + (dir / "surface_faces.csv").string());
    out.files["faces"] = "surface_faces.csv";
  }
  for (const auto& f : p.formats) {
    const std::string name = "surface." + f;
    std::ofstream os(dir / name, std::ios::binary);
    meshWriter(f)(os, mesh);
    if (!os) throw std::runtime_error("cannot write " + (dir / name).string());
    out.files[f] = name;
  }
  std::int64_t trees = 0, segments = 0;
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i) trees += tree.isRoot(i), segments += !tree.isRoot(i) && !tree.isLink(i);
  out.parameters = {{"formats", p.formats},
                    {"method", p.method},
                    {"junctions", tubes ? Json(p.junctions) : Json(nullptr)},
                    {"voxel_mm", p.voxel_mm ? Json(*p.voxel_mm) : Json(nullptr)},
                    {"samples_across", o.samples_across},
                    {"ring_spacing_radii", tubes && p.ringSpacing() > 0 ? Json(p.ringSpacing()) : Json(nullptr)},
                    {"ring_spacing_vertex_spacings", tubes && p.ringSpacing() == 0 ? Json(kCfdRingSpacing) : Json(nullptr)},
                    {"wall", !walls ? Json(nullptr)
                                    : p.wall_thickness > 0 ? Json({{"thickness_mm", p.wall_thickness}})
                                    : p.wall_ratio > 0     ? Json({{"ratio_of_radius", p.wall_ratio}})
                                                           : Json({{"from", "the graph's wall values"}})},
                    {"adaptive", !p.uniform},
                    {"volume_restored", !p.on_surface},
                    {"ends", walls ? std::string("open") : p.ends},
                    {"flow_extension_radii", p.flow_extension},
                    {"clip_box_mm", p.clip_box.empty() ? Json(nullptr) : Json(p.clip_box)},
                    {"decimate", p.decimate},
                    {"max_error_steps", p.max_error},
                    {"sliver_angle_deg", p.sliverAngle()},
                    {"max_angle_deg", p.maxAngle()},
                    {"remesh", tubes && p.remeshes()},
                    {"description", tubes ? "each vessel's free middle a tube of rings on its exact wall (at most ring_spacing_radii radii "
                                            "apart, aligned; or ring_spacing_vertex_spacings apart, each turned by half a vertex spacing); where vessels meet, the signed distance to the union of their capsules and round cones "
                                            "contoured by surface nets on a uniform grid or on the octree (junctions = nets, where the part passes its checks) or "
                                            "by marching tetrahedra (2:1-balanced octree of cells sized to each vessel's radius), cut by "
                                            "planes across the tubes and joined to their rings"
                                          : "marching tetrahedra of the signed distance to the union of each tree's capsules and round cones, on a "
                                            "2:1-balanced octree of cells sized to each vessel's radius, split into conforming tetrahedra"}};
  out.statistics = {{"trees", trees},
                    {"segments", segments},
                    {"vertices", mesh.vertices.size()},
                    {"triangles", mesh.triangles.size()},
                    {"triangles_per_segment", segments > 0 ? double(mesh.triangles.size()) / double(segments) : 0.0},
                    {"finest_step_mm", report.voxel_mm},
                    {"coarsest_cell_mm", tubes ? Json(nullptr) : Json(report.coarsest_mm)},
                    {"levels", tubes ? Json(nullptr) : Json(report.levels)},
                    {"cells", tubes ? Json(nullptr) : Json(report.cells)},
                    {"largest_volume_move_mm", tubes ? Json(nullptr) : Json(report.largest_volume_move_mm)},
                    {"tubes", tubes ? Json(tube_report.tubes) : Json(nullptr)},
                    {"contoured_parts", tubes ? Json(tube_report.clusters) : Json(nullptr)},
                    {"parts_by_nets", tubes ? Json(tube_report.netted) : Json(nullptr)},
                    {"largest_contoured_part_vessels", tubes ? Json(tube_report.largest_cluster_vessels) : Json(nullptr)},
                    {"tube_triangles", tubes ? Json(tube_report.tube_triangles) : Json(nullptr)},
                    {"contoured_triangles", tubes ? Json(tube_report.contour_triangles) : Json(nullptr)},
                    {"tubes_given_up", tubes ? Json(tube_report.fallbacks) : Json(nullptr)},
                    {"cuts_retried", tubes ? Json(tube_report.cut_retries) : Json(nullptr)},
                    {"wall_ends_joined", walls ? Json(wall_report.rings) : Json(nullptr)},
                    {"estimated_bytes", report.estimated_bytes},
                    {"enclosed_volume_mm3", topo.volume_mm3},
                    {"boundary_edges", topo.boundary_edges},
                    {"nonmanifold_edges", topo.nonmanifold_edges},
                    {"misoriented_edges", topo.misoriented_edges},
                    {"degenerate_triangles", topo.degenerate_triangles},
                    {"cavities_removed", tubes ? tube_report.cavities_removed : report.cavities_removed},
                    {"triangles_before_decimation", p.decimate ? Json(reduced.before) : Json(nullptr)},
                    {"decimation_collapses", reduced.collapses},
                    {"decimation_largest_error_mm", reduced.largest_error_mm},
                    {"slivers_repaired", tubes ? tube_report.slivers_repaired : slivers.changes()},
                    {"remesh_splits", tube_report.remesh_splits},
                    {"remesh_changes", tube_report.remesh_changes},
                    {"ends", ends.size()},
                    {"ends_cut", cut.cut},
                    {"ends_left_closed", cut.left_closed.size()},
                    {"clip_box_removed_triangles", p.clip_box.empty() ? Json(nullptr) : Json(clipped.removed_triangles)},
                    {"clip_box_section_loops", p.clip_box.empty() ? Json(nullptr) : Json(clipped.section_loops)},
                    {"clip_box_section_area_mm2", p.clip_box.empty() ? Json(nullptr) : Json(clipped.section_area_mm2)},
                    {"tree_components", topo.tree_components},
                    {"tree_euler_characteristic", topo.tree_euler}};
  return out;
}

}  // namespace angiosynth
