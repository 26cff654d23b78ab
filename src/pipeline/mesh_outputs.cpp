#include "pipeline/mesh_outputs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <tuple>

#include "core/error.hpp"
#include "io/mesh_writers.hpp"
#include "core/format.hpp"
#include "core/segment_grid.hpp"
#include "grow/common/intersections.hpp"
#include "mesh/box_clip.hpp"
#include "mesh/decimate.hpp"
#include "mesh/hollow_wall.hpp"
#include "mesh/tube_surface.hpp"
#include "mesh/vessel_ends.hpp"
#include "mesh/vessel_surface.hpp"

namespace angiosynth {

using Json = nlohmann::ordered_json;

namespace {

// Per end: 1 where the cut left it closed.
std::vector<char> leftClosed(const EndCutReport& cut, std::size_t ends) {
  std::vector<char> closed(ends, 0);
  for (auto e : cut.left_closed) closed[std::size_t(e)] = 1;
  return closed;
}

// surface_faces.csv: one row per face label (the wall, then each end), as the ids the VTP and
// PLY files carry (ModelFaceID = CellEntityIds = face + 1).
// With a clip box, an end outside it is `outside_box`, and each side of the box has a row (kind
// `box`, end its side, the section's area).
void writeFaces(std::ostream& os, const std::vector<VesselEnd>& ends, const EndCutReport& cut, const std::string& mode,
                const std::vector<std::string>& kinds, const std::vector<std::string>& vessel_ids, const std::vector<double>& box,
                const BoxClipReport& clipped) {
  os << "face_id,kind,tree,vessel,end,state,centre_x,centre_y,centre_z,normal_x,normal_y,normal_z,radius,cap_area,loop_vertices,extension_radii\n";
  os << "1,wall,,,,,,,,,,,,,,\n";
  const auto closed = leftClosed(cut, ends.size());
  const auto outside = [&](const Vec3& c) {
    return !box.empty() && (c.x < box[0] || c.y < box[1] || c.z < box[2] || c.x > box[3] || c.y > box[4] || c.z > box[5]);
  };
  for (std::size_t k = 0; k < ends.size(); ++k) {
    const auto& e = ends[k];
    const bool vein = std::size_t(e.tree) < kinds.size() && kinds[std::size_t(e.tree)] == "vein";
    os << k + 2 << ',' << ((e.root != vein) ? "inlet" : "outlet") << ',' << e.tree << ','
       << (std::size_t(e.vessel) < vessel_ids.size() ? vessel_ids[std::size_t(e.vessel)] : std::to_string(e.vessel)) << ','
       << (e.root ? "root" : "leaf") << ','
       << (outside(e.centre) ? "outside_box"
           : closed[k]       ? "left_closed"
                             : mode)
       << ',' << exactNumber(e.centre.x) << ',' << exactNumber(e.centre.y) << ',' << exactNumber(e.centre.z) << ',' << exactNumber(e.normal.x) << ','
       << exactNumber(e.normal.y) << ',' << exactNumber(e.normal.z) << ',' << exactNumber(e.radius) << ',' << exactNumber(cut.cap_area_mm2[k]) << ','
       << cut.loop_vertices[k] << ',' << exactNumber(e.extension_radii) << '\n';
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
    os << ",," << exactNumber(clipped.section_area_mm2[std::size_t(side)]) << ",,\n";
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
    for (int i = 0; i < 3; ++i)
      edges.push_back({f, std::min(t[std::size_t(i)], t[std::size_t((i + 1) % 3)]), std::max(t[std::size_t(i)], t[std::size_t((i + 1) % 3)])});
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

// At least two grid steps across the thinnest vessel: coarser, its surface falls between the
// samples and comes out empty, or its volume wrong by a tenth and more.
void checkVoxelAgainstThinnest(const VascularTree& tree, const MeshParameters& p) {
  if (!p.voxel_mm) return;
  double thinnest = INFINITY;
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i)
    if (!tree.isRoot(i) && !tree.isLink(i)) thinnest = std::min({thinnest, tree.radius[i], tree.startRadius(i)});
  if (*p.voxel_mm > thinnest)
    throw InputError("", 0,
                     "a mesh voxel of " + exactNumber(*p.voxel_mm) + " mm is coarser than half the thinnest vessel's diameter (" +
                         exactNumber(2 * thinnest) + " mm); allowed: at most " + exactNumber(thinnest) + " mm, two steps across it");
}

double smallestAngleDeg(const Vec3& a, const Vec3& b, const Vec3& c) {
  const auto corner = [](const Vec3& p, const Vec3& q, const Vec3& r) {
    const double l = norm(q - p) * norm(r - p);
    return l > 0 ? std::acos(std::clamp(dot(q - p, r - p) / l, -1.0, 1.0)) : 0.0;
  };
  return std::min({corner(a, b, c), corner(b, c, a), corner(c, a, b)}) * 180 / M_PI;
}

// The meshers' options, from the settings.
struct SurfacePlan {
  bool tubes = false, walls = false, cut_ends = false;
  WallThickness wall;
  SurfaceOptions contour;   // the contour method's, and the tubes' junctions'
  TubeSurfaceOptions tube;  // the tube surface's and a hollow wall's two (whose ends are open); its
                            // ends and decimation serve the contour method too
  const std::vector<VesselEnd>& ends() const { return tube.ends; }
};

SurfacePlan planSurface(const VascularTree& tree, const MeshParameters& p, std::uint64_t memory_limit) {
  SurfacePlan plan;
  plan.tubes = p.method == "tubes";
  plan.wall = WallThickness{p.wall_thickness, p.wall_ratio, p.wall_from_graph};
  plan.walls = plan.wall.any();
  SurfaceOptions& o = plan.contour;
  o.voxel_mm = p.voxel_mm.value_or(0);
  o.samples_across = p.samples_across.value_or(plan.tubes ? 3 : 4);
  o.adaptive = !p.uniform;
  o.restore_volume = !p.on_surface;
  o.memory_limit = memory_limit;
  plan.cut_ends = p.ends != "closed" || plan.walls;  // a hollow wall's ends are open
  TubeSurfaceOptions& to = plan.tube;
  // An end's step: its diameter over the samples across it (what the adaptive contour gives it).
  if (plan.cut_ends) to.ends = openEnds(tree, p.flow_extension, 2.0 / o.samples_across);
  DecimateOptions& d = to.decimation;
  d.max_error = p.max_error;
  d.sliver_deg = p.sliverAngle();
  d.obtuse_deg = p.maxAngle();
  to.junction = o;
  to.ring_spacing_radii = p.ringSpacing();
  to.cap_ends = !plan.walls && p.ends == "capped";
  to.decimate = p.decimate;
  to.nets = p.junctions == "nets";
  to.remesh = p.remeshes();
  return plan;
}

// The surface and what its mesher reported: a hollow wall, tubes with contoured junctions, or
// one contour of the whole tree (with its sliver repair, end cuts and decimation).
struct BuiltSurface {
  SurfaceMesh mesh;
  SurfaceReport contour;
  TubeSurfaceReport tube;
  HollowWallReport wall;
  EndCutReport cut;
  DecimateReport reduced, slivers;
  BoxClipReport clipped;
};

BuiltSurface buildSurface(const VascularTree& tree, const MeshParameters& p, SurfacePlan& plan,
                          const std::function<void(std::int64_t, std::int64_t)>& progress) {
  BuiltSurface b;
  const auto& ends = plan.ends();
  if (plan.walls) {
    b.mesh = hollowWall(tree, plan.tube, plan.wall, &b.wall, progress);
    b.tube = b.wall.outer;
    b.contour.voxel_mm = std::min(b.wall.outer.finest_step_mm, b.wall.lumen.finest_step_mm);
    b.contour.estimated_bytes = std::max(b.wall.outer.estimated_bytes, b.wall.lumen.estimated_bytes);
    b.cut.cut = b.wall.rings;
    b.cut.left_closed = b.wall.not_joined;
    // A ring's loop vertices: its two loops' together.
    b.cut.cap_area_mm2 = endFaceAreas(b.mesh, ends.size(), &b.cut.loop_vertices);
  } else if (plan.tubes) {
    b.mesh = tubeSurface(tree, plan.tube, &b.tube, progress);
    b.cut = b.tube.ends;
    b.contour.voxel_mm = b.tube.finest_step_mm;
    b.contour.estimated_bytes = b.tube.estimated_bytes;
    b.reduced.before = b.tube.triangles_before_decimation + b.tube.tube_triangles;
    b.reduced.collapses = b.tube.decimation_collapses;
    b.reduced.largest_error_mm = b.tube.decimation_largest_error_mm;
  } else {
    const DecimateOptions& d = plan.tube.decimation;
    plan.contour.finish = [&](SurfaceMesh& m, const std::function<double(std::int32_t, const Vec3&)>& distance) {
      // Slivers before the cut too (tube_surface.cpp says why).
      if (d.sliver_deg > 0) b.slivers = repairSlivers(m, d, distance);
      if (plan.cut_ends) b.cut = cutEnds(m, ends, p.ends == "capped");
      if (p.decimate)
        b.reduced = decimate(m, d, distance);
      else if (d.sliver_deg > 0)
        b.slivers += repairSlivers(m, d, distance, nullptr, true);
    };
    b.mesh = vesselSurface(plan.cut_ends ? prolongEnds(tree, ends) : tree, plan.contour, &b.contour, progress);
    plan.contour.finish = nullptr;  // it refers to this function's locals
  }
  // The caps as made: the sliver repair may join two of a cap's loop vertices.
  if (p.ends == "capped" && !plan.walls) b.cut.cap_area_mm2 = endFaceAreas(b.mesh, ends.size(), &b.cut.loop_vertices);
  if (!p.clip_box.empty()) {
    const auto& box = p.clip_box;
    b.clipped = clipToBox(b.mesh, Vec3(box[0], box[1], box[2]), Vec3(box[3], box[4], box[5]), std::int32_t(ends.size()) + 1);
    // What is left of each end's face (a box side may cut it; outside the box it is gone).
    if (plan.cut_ends) b.cut.cap_area_mm2 = endFaceAreas(b.mesh, ends.size());
  }
  if (b.mesh.triangles.empty() && p.clip_box.empty()) throw std::logic_error("the surface of a tree with vessels came out empty");
  return b;
}

SurfaceSummary summarise(const VascularTree& tree, const MeshParameters& p, const SurfacePlan& plan, const BuiltSurface& b) {
  SurfaceSummary s;
  const bool tubes = plan.tubes, clip = !p.clip_box.empty();
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i) s.trees += tree.isRoot(i), s.segments += !tree.isRoot(i) && !tree.isLink(i);
  s.vertices = std::int64_t(b.mesh.vertices.size());
  s.triangles = std::int64_t(b.mesh.triangles.size());
  s.finest_step_mm = b.contour.voxel_mm;
  if (!tubes) {
    s.contour = SurfaceSummary::Contour{b.contour.coarsest_mm, b.contour.levels, b.contour.cells, b.contour.largest_volume_move_mm};
  } else {
    const auto& t = b.tube;
    s.tube = SurfaceSummary::Tubes{t.tubes,          t.clusters,          t.netted,    t.largest_cluster_vessels,
                                   t.tube_triangles, t.contour_triangles, t.fallbacks, t.cut_retries};
  }
  if (plan.walls) s.wall_ends_joined = b.wall.rings;
  s.estimated_bytes = b.contour.estimated_bytes;
  s.topology = meshTopology(b.mesh);
  s.cavities_removed = tubes ? b.tube.cavities_removed : b.contour.cavities_removed;
  if (p.decimate) s.triangles_before_decimation = b.reduced.before;
  s.decimation_collapses = b.reduced.collapses;
  s.decimation_largest_error_mm = b.reduced.largest_error_mm;
  s.sliver_repair_changes = tubes ? b.tube.slivers_repaired : b.slivers.changes();
  s.smallest_angle_deg = 180;
  for (const auto& t : b.mesh.triangles) {
    const double a = smallestAngleDeg(b.mesh.vertices[std::size_t(t[0])], b.mesh.vertices[std::size_t(t[1])], b.mesh.vertices[std::size_t(t[2])]);
    s.smallest_angle_deg = std::min(s.smallest_angle_deg, a);
    s.triangles_below_sliver_angle += p.sliverAngle() > 0 && a < p.sliverAngle();
  }
  s.remesh_splits = b.tube.remesh_splits;
  s.remesh_changes = b.tube.remesh_changes;
  s.ends = std::int64_t(plan.ends().size());
  s.ends_cut = b.cut.cut;
  s.ends_left_closed = std::int64_t(b.cut.left_closed.size());
  for (const auto& e : plan.ends()) s.ends_extension_shortened += e.extension_stop >= 0;
  if (clip) s.clip = b.clipped;
  if (!plan.walls && !clip) {
    s.tree_euler_expected.assign(s.topology.tree_euler.size(), 2);
    const auto closed = leftClosed(b.cut, plan.ends().size());
    for (std::size_t k = 0; k < plan.ends().size(); ++k)
      if (p.ends == "open" && !closed[k] && std::size_t(plan.ends()[k].tree) < s.tree_euler_expected.size())
        --s.tree_euler_expected[std::size_t(plan.ends()[k].tree)];
  }
  return s;
}

std::string vesselName(std::int32_t v, const std::vector<std::string>& vessel_ids) {
  return "vessel " + (std::size_t(v) < vessel_ids.size() ? vessel_ids[std::size_t(v)] : std::to_string(v));
}

std::string endName(std::size_t k, const VesselEnd& e, const std::vector<std::string>& vessel_ids) {
  return std::string(e.root ? "the root" : "the leaf") + " end of " + vesselName(e.vessel, vessel_ids) + " at (" + show(e.node.x) + ", " +
         show(e.node.y) + ", " + show(e.node.z) + ") mm (face_id " + std::to_string(k + 2) + ")";
}

// Vessel pairs of a tree, more than two segments apart, whose walls come within a contour step
// of each other (the thinner one's: its diameter over `samples_across`), the nearest first: the
// surface joins them into a handle though their capsules need not overlap.
std::vector<std::pair<std::int32_t, std::int32_t>> nearlyTouching(const VascularTree& tree, double samples_across) {
  Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  std::vector<double> lengths;
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i) {
    lo = componentMin(lo, tree.position[i]), hi = componentMax(hi, tree.position[i]);
    if (!tree.isRoot(i) && !tree.isLink(i)) lengths.push_back(distance(tree.position[i], tree.position[tree.parent[i]]));
  }
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  std::vector<std::tuple<double, std::int32_t, std::int32_t>> found;  // (gap in steps, x, y)
  if (lengths.empty()) return pairs;
  std::nth_element(lengths.begin(), lengths.begin() + std::ptrdiff_t(lengths.size() / 2), lengths.end());
  const auto wall = [&](std::int32_t i) { return std::max(tree.radius[i], tree.startRadius(i)); };
  const auto step = [&](std::int32_t i) { return 2 * wall(i) / samples_across; };
  SegmentGrid grid(lo, hi, std::max(lengths[lengths.size() / 2], 1e-6), hi.z - lo.z <= 0);
  for (std::int32_t i = 0; i < tree.nodeCount(); ++i)
    if (!tree.isRoot(i) && !tree.isLink(i)) grid.insert(i, tree.position[tree.parent[i]], tree.position[i], wall(i) + step(i));
  for (std::int32_t x = 0; x < tree.nodeCount(); ++x) {
    if (tree.isRoot(x) || tree.isLink(x)) continue;
    const Vec3 a = tree.position[tree.parent[x]], b = tree.position[x];
    grid.any(a, b, wall(x) + step(x), [&](std::int32_t y) {
      if (y <= x || (!tree.tree.empty() && tree.tree[x] != tree.tree[y]) || withinTwoSegments(tree, x, y)) return false;
      const double gap = segmentSegmentDistance(a, b, tree.position[tree.parent[y]], tree.position[y]) - wall(x) - wall(y);
      const double share = gap / std::min(step(x), step(y));
      if (share < 1 && !joinedAlongVessel(tree, x, y, wall(x) + wall(y))) found.push_back({share, x, y});
      return false;
    });
  }
  std::sort(found.begin(), found.end());  // the nearest first
  for (const auto& [share, x, y] : found) pairs.emplace_back(x, y);
  return pairs;
}

// The summary's warnings: ends the mesher could not do as asked, and trees whose surface has
// another topology than their graph, with the vessel pairs whose walls overlap in that tree.
std::vector<std::string> surfaceWarnings(const VascularTree& tree, const SurfacePlan& plan, const BuiltSurface& b, const SurfaceSummary& s,
                                         const std::vector<std::string>& vessel_ids, double samples_across) {
  std::vector<std::string> out, per_end;  // the trees' first: an end's warning explains less
  const auto& ends = plan.ends();
  for (std::size_t k = 0; k < ends.size(); ++k)
    if (ends[k].extension_stop >= 0)
      per_end.push_back(endName(k, ends[k], vessel_ids) + ": flow extension shortened to " + show(ends[k].extension_radii, 3) +
                        " radii; a longer one would come near enough for the surface to join it to " +
                        vesselName(ends[k].extension_stop, vessel_ids));
  for (auto k : b.cut.left_closed)
    per_end.push_back(endName(std::size_t(k), ends[std::size_t(k)], vessel_ids) +
                      ": left closed (round, face 'left_closed' in surface_faces.csv): another vessel's wall lies within its cut's reach");
  std::vector<std::pair<std::int32_t, std::int32_t>> overlaps;
  bool computed = false;
  for (std::size_t t = 0; t < s.tree_euler_expected.size(); ++t) {
    const auto chi = s.topology.tree_euler[t], want = s.tree_euler_expected[t];
    const auto parts = t < s.topology.tree_components.size() ? s.topology.tree_components[t] : 0;
    if (parts == 0 || (chi == want && parts == 1)) continue;
    std::string w = "tree " + std::to_string(t) + ": the surface has Euler characteristic " + std::to_string(chi) + " in " + counted(parts, "piece") +
                    ", not " + std::to_string(want) + " in one piece as its graph implies";
    if (chi < want) w += ": " + counted((want - chi + 1) / 2, "handle") + " where vessels fuse";
    if (!computed) {
      overlaps = nearlyTouching(tree, samples_across);
      computed = true;
    }
    std::vector<std::string> named;
    std::size_t in_tree = 0;
    for (const auto& [x, y] : overlaps)
      if (std::size_t(tree.tree.empty() ? 0 : tree.tree[x]) == t && in_tree++ < 5)
        named.push_back(vesselName(x, vessel_ids) + " and " + vesselName(y, vessel_ids));
    if (in_tree > named.size()) named.push_back(std::to_string(in_tree - named.size()) + " more pairs");
    if (!named.empty()) {
      w += " (walls within a contour step of each other:";
      for (std::size_t i = 0; i < named.size(); ++i) w += (i ? ", " : " ") + named[i];
      w += ")";
    }
    out.push_back(w + "; do not mesh its volume before removing them");
  }
  out.insert(out.end(), per_end.begin(), per_end.end());
  return out;
}

// The settings as the meshers took them (defaults resolved) and how the surface is made.
Json resolvedParameters(const MeshParameters& p, const SurfacePlan& plan) {
  const bool tubes = plan.tubes, walls = plan.walls;
  return {
      {"formats", p.formats},
      {"method", p.method},
      {"junctions", tubes ? Json(p.junctions) : Json(nullptr)},
      {"voxel_mm", p.voxel_mm ? Json(*p.voxel_mm) : Json(nullptr)},
      {"samples_across", plan.contour.samples_across},
      {"ring_spacing_radii", tubes && p.ringSpacing() > 0 ? Json(p.ringSpacing()) : Json(nullptr)},
      {"ring_spacing_vertex_spacings", tubes && p.ringSpacing() == 0 ? Json(kCfdRingSpacing) : Json(nullptr)},
      {"wall", !walls                 ? Json(nullptr)
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
                              "apart, aligned; or ring_spacing_vertex_spacings apart, each turned by half a vertex spacing); where vessels meet, the "
                              "signed distance to the union of their capsules and round cones "
                              "contoured by surface nets on a uniform grid or on the octree (junctions = nets, where the part passes its checks) or "
                              "by marching tetrahedra (2:1-balanced octree of cells sized to each vessel's radius), cut by "
                              "planes across the tubes and joined to their rings"
                            : "marching tetrahedra of the signed distance to the union of each tree's capsules and round cones, on a "
                              "2:1-balanced octree of cells sized to each vessel's radius, split into conforming tetrahedra"}};
}

void writeFile(const std::filesystem::path& file, const std::function<void(std::ostream&)>& write) {
  std::ofstream os(file, std::ios::binary);
  write(os);
  if (!os) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace

Json SurfaceSummary::toJson() const {
  const auto opt = [](const auto& v, auto get) { return v ? Json(get(*v)) : Json(nullptr); };
  const auto& t = topology;
  return {{"trees", trees},
          {"segments", segments},
          {"vertices", vertices},
          {"triangles", triangles},
          {"triangles_per_segment", segments > 0 ? double(triangles) / double(segments) : 0.0},
          {"finest_step_mm", finest_step_mm},
          {"coarsest_cell_mm", opt(contour, [](const Contour& c) { return c.coarsest_cell_mm; })},
          {"levels", opt(contour, [](const Contour& c) { return c.levels; })},
          {"cells", opt(contour, [](const Contour& c) { return c.cells; })},
          {"largest_volume_move_mm", opt(contour, [](const Contour& c) { return c.largest_volume_move_mm; })},
          {"tubes", opt(tube, [](const Tubes& c) { return c.tubes; })},
          {"contoured_parts", opt(tube, [](const Tubes& c) { return c.contoured_parts; })},
          {"parts_by_nets", opt(tube, [](const Tubes& c) { return c.parts_by_nets; })},
          {"largest_contoured_part_vessels", opt(tube, [](const Tubes& c) { return c.largest_contoured_part_vessels; })},
          {"tube_triangles", opt(tube, [](const Tubes& c) { return c.tube_triangles; })},
          {"contoured_triangles", opt(tube, [](const Tubes& c) { return c.contoured_triangles; })},
          {"tubes_given_up", opt(tube, [](const Tubes& c) { return c.given_up; })},
          {"cuts_retried", opt(tube, [](const Tubes& c) { return c.cuts_retried; })},
          {"wall_ends_joined", opt(wall_ends_joined, [](std::int64_t v) { return v; })},
          {"estimated_bytes", estimated_bytes},
          {"enclosed_volume_mm3", t.volume_mm3},
          {"boundary_edges", t.boundary_edges},
          {"nonmanifold_edges", t.nonmanifold_edges},
          {"misoriented_edges", t.misoriented_edges},
          {"degenerate_triangles", t.degenerate_triangles},
          {"cavities_removed", cavities_removed},
          {"triangles_before_decimation", opt(triangles_before_decimation, [](std::int64_t v) { return v; })},
          {"decimation_collapses", decimation_collapses},
          {"decimation_largest_error_mm", decimation_largest_error_mm},
          {"sliver_repair_changes", sliver_repair_changes},
          {"smallest_angle_deg", smallest_angle_deg},
          {"triangles_below_sliver_angle", triangles_below_sliver_angle},
          {"remesh_splits", remesh_splits},
          {"remesh_changes", remesh_changes},
          {"ends", ends},
          {"ends_cut", ends_cut},
          {"ends_left_closed", ends_left_closed},
          {"ends_extension_shortened", ends_extension_shortened},
          {"clip_box_removed_triangles", opt(clip, [](const BoxClipReport& c) { return c.removed_triangles; })},
          {"clip_box_section_loops", opt(clip, [](const BoxClipReport& c) { return c.section_loops; })},
          {"clip_box_section_area_mm2", opt(clip, [](const BoxClipReport& c) { return c.section_area_mm2; })},
          {"tree_components", t.tree_components},
          {"tree_euler_characteristic", t.tree_euler},
          {"tree_euler_expected", tree_euler_expected.empty() ? Json(nullptr) : Json(tree_euler_expected)},
          {"warnings", warnings}};
}

SurfaceFiles writeSurfaceFiles(const VascularTree& tree, const MeshParameters& p, std::uint64_t memory_limit, const std::filesystem::path& dir,
                               const std::function<void(std::int64_t, std::int64_t)>& progress, const std::vector<std::string>& tree_kinds,
                               const std::vector<std::string>& vessel_ids) {
  checkVoxelAgainstThinnest(tree, p);
  SurfacePlan plan = planSurface(tree, p, memory_limit);
  const BuiltSurface built = buildSurface(tree, p, plan, progress);
  SurfaceFiles out;
  out.files = Json::object();
  if (plan.cut_ends || !p.clip_box.empty()) {
    writeFile(dir / "surface_faces.csv", [&](std::ostream& os) {
      writeFaces(os, plan.ends(), built.cut, plan.walls ? "open" : p.ends, tree_kinds, vessel_ids, p.clip_box, built.clipped);
    });
    out.files["faces"] = "surface_faces.csv";
  }
  for (const auto& f : p.formats) {
    const std::string name = "surface." + f;
    writeFile(dir / name, [&](std::ostream& os) { meshWriter(f)(os, built.mesh); });
    out.files[f] = name;
  }
  out.parameters = resolvedParameters(p, plan);
  out.statistics = summarise(tree, p, plan, built);
  out.statistics.warnings = surfaceWarnings(tree, plan, built, out.statistics, vessel_ids, plan.contour.samples_across);
  return out;
}

}  // namespace angiosynth
