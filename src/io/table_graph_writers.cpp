// Tabular and XML graph exports: VesselGraph CSV, VTK PolyData, SWC, GraphML.
#include <numbers>

#include "core/format.hpp"
#include "core/vessel_roles.hpp"
#include "io/graph_writers.hpp"

namespace angiosynth {

double nodeRadius(const VascularTree& t, std::int32_t i) {
  if (!t.isRoot(i)) return t.radius[i];
  return t.child0[i] > 0 ? t.startRadius(t.child0[i]) : 0.0;
}

double segmentVolume(const VascularTree& t, std::int32_t i) {
  const double r = t.radius[i], l = t.length[i];
  if (t.radius_start[i] < 0) return std::numbers::pi * r * r * l;
  const double a = t.radius_start[i];
  return std::numbers::pi * l * (a * a + a * r + r * r) / 3;  // a truncated cone
}

void writeNodesCsv(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees) {
  out << "id,pos_x,pos_y,pos_z,type,pressure,tree,kind\n";
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) continue;
    const Vec3& p = t.position[i];
    const TreeInfo& tr = treeOf(trees, t, i);
    out << i << ',' << exactNumber(p.x) << ',' << exactNumber(p.y) << ',' << exactNumber(p.z) << ',' << nodeTypeName(t.graphType(i)) << ','
        << exactNumber(t.pressure[i]) << ',' << tr.id << ',' << tr.kind << '\n';
  }
}

void writeEdgesCsv(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees) {
  const bool staged = t.hasStages(), tapered = t.hasTapers() || t.hasWalls();
  out << "id,node1id,node2id,length,radius,flow,volume,tree,kind" << (staged ? ",stage,role,branching" : "")
      << (tapered ? ",radius_start,wall_start,wall" : "") << "\n";
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    const TreeInfo& tr = treeOf(trees, t, i);
    out << i << ',' << t.junction(t.parent[i]) << ',' << i << ',' << exactNumber(t.length[i]) << ',' << exactNumber(t.radius[i]) << ','
        << exactNumber(t.flow[i]) << ',' << exactNumber(segmentVolume(t, i)) << ',' << tr.id << ',' << tr.kind;
    if (staged) out << ',' << t.stage[i] << ',' << roleName(t.role[i]) << ',' << branchingName(t.branching[i]);
    if (tapered) out << ',' << exactNumber(t.startRadius(i)) << ',' << exactNumber(t.wall_start[i]) << ',' << exactNumber(t.wall[i]);
    out << '\n';
  }
}

namespace {

// The cell arrays VItA's VTK writer names (VItA, the public code of Maso Talou et al. 2021), with its codes, so scripts
// written for VItA's trees read ours: vesselFunction 0 distribution, 1 perforator, 2 transport;
// branchingType 0 none, 1 rigid (fixed), 2 deformable (versatile), 3 distal; pressure at the
// proximal end (Pa here), level from 0 at the root vessel, ID_Vessel our segment id.
void writeVitaCellArrays(std::ostream& out, const VascularTree& t, const std::vector<std::int32_t>& segments) {
  const auto array = [&](const char* name, auto&& value) {
    out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (auto i : segments) out << exactNumber(double(value(i))) << '\n';
  };
  array("radius", [&](std::int32_t i) { return t.radius[i]; });
  array("flow", [&](std::int32_t i) { return t.flow[i]; });
  array("pressure", [&](std::int32_t i) { return t.pressure[t.parent[i]]; });
  array("length", [&](std::int32_t i) { return t.length[i]; });
  array("beta", [&](std::int32_t i) { return t.beta[i]; });
  array("geomConst", [&](std::int32_t i) { return t.length[i] - 2 * t.radius[i]; });
  array("level", [&](std::int32_t i) { return t.depth[i] - 1; });
  array("ID_Vessel", [&](std::int32_t i) { return i; });
  array("stage", [&](std::int32_t i) { return t.stage[i]; });
  array("vesselFunction", [&](std::int32_t i) {
    switch (VesselRole(t.role[i])) {
      case VesselRole::Perforator: return 1;
      case VesselRole::Transport: return 2;
      default: return 0;
    }
  });
  array("branchingType", [&](std::int32_t i) {
    switch (Branching(t.branching[i])) {
      case Branching::None: return 0;
      case Branching::Fixed: return 1;
      case Branching::Distal: return 3;
      default: return 2;
    }
  });
}

}  // namespace

void writeVtp(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees) {
  // Points: the nodes but links (an N-ary junction is one point), numbered in node order.
  std::vector<std::int32_t> points, point_of(std::size_t(t.nodeCount()), -1), segments;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (!t.isLink(i)) point_of[std::size_t(i)] = std::int32_t(points.size()), points.push_back(i);
  for (std::int32_t i = 1; i < t.nodeCount(); ++i)
    if (!t.isRoot(i) && !t.isLink(i)) segments.push_back(i);
  const auto n = std::int32_t(points.size());
  const auto treeIndex = [&](std::int32_t i) { return t.tree.empty() ? 0 : t.tree[i]; };
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      << "<Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"0\" NumberOfLines=\"" << segments.size()
      << "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
      << "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (auto i : points) out << exactNumber(t.position[i].x) << ' ' << exactNumber(t.position[i].y) << ' ' << exactNumber(t.position[i].z) << '\n';
  // A segment is a cylinder: its radius is the cell's (active scalars). Per point, for viewers
  // that need point radii, the radius of the segment ending there, named so it is not mistaken
  // for the vessel's (interpolated between points it tapers every vessel).
  out << "</DataArray>\n</Points>\n<PointData>\n<DataArray type=\"Float64\" Name=\"NodeRadius\" format=\"ascii\">\n";
  for (auto i : points) out << exactNumber(nodeRadius(t, i)) << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"Tree\" format=\"ascii\">\n";
  for (auto i : points) out << treeIndex(i) << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"Class\" format=\"ascii\">\n";
  for (auto i : points) out << treeOf(trees, t, i).class_label << '\n';
  out << "</DataArray>\n</PointData>\n<CellData Scalars=\"Radius\">\n<DataArray type=\"Float64\" Name=\"Radius\" format=\"ascii\">\n";
  for (auto i : segments) out << exactNumber(t.radius[i]) << '\n';
  out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"Flow\" format=\"ascii\">\n";
  for (auto i : segments) out << exactNumber(t.flow[i]) << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"Tree\" format=\"ascii\">\n";
  for (auto i : segments) out << treeIndex(i) << '\n';
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"Class\" format=\"ascii\">\n";
  for (auto i : segments) out << treeOf(trees, t, i).class_label << '\n';
  if (t.hasStages()) {  // staged growth: stage from 0, role 1 distribution, 2 transport, 3 perforator; branching 1 versatile, 2 fixed, 3 distal, 4 none
    for (const auto& [name, value] : {std::pair<const char*, int>{"Stage", 0}, {"Role", 1}, {"Branching", 2}}) {
      out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (auto i : segments) out << (value == 0 ? int(t.stage[i]) : value == 1 ? int(t.role[i]) : int(t.branching[i])) << '\n';
    }
    writeVitaCellArrays(out, t, segments);
  }
  if (t.hasTapers() || t.hasWalls()) {  // tapered vessels (Lázaro 2011): the proximal radius, the wall at both ends
    const auto array = [&](const char* name, auto&& value) {
      out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"" << name << "\" format=\"ascii\">\n";
      for (auto i : segments) out << exactNumber(value(i)) << '\n';
    };
    array("RadiusStart", [&](std::int32_t i) { return t.startRadius(i); });
    array("WallStart", [&](std::int32_t i) { return t.wall_start[i]; });
    array("Wall", [&](std::int32_t i) { return t.wall[i]; });
  }
  out << "</DataArray>\n</CellData>\n<Lines>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (auto i : segments) out << point_of[std::size_t(t.junction(t.parent[i]))] << ' ' << point_of[std::size_t(i)] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t k = 1; k <= segments.size(); ++k) out << 2 * k << '\n';
  out << "</DataArray>\n</Lines>\n</Piece>\n</PolyData>\n</VTKFile>\n";
}

void writeSwc(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees) {
  out << "# angiosynth vascular forest; x y z R in mm; type 1 = root, 1 + class for vessel nodes (2 artery, 3 vein, "
         "further kinds on)\n";
  // SWC ids start at 1 and a parent must precede its children.
  std::vector<std::int32_t> order;
  for (auto i : t.topDownOrder())
    if (!t.isLink(i)) order.push_back(i);  // an N-ary junction is one sample
  std::vector<std::int64_t> id(t.nodeCount(), -1);
  for (std::size_t k = 0; k < order.size(); ++k) id[order[k]] = std::int64_t(k) + 1;
  for (auto i : order) {
    const Vec3& p = t.position[i];
    const bool root = t.isRoot(i);
    out << id[i] << ' ' << (root ? 1 : 1 + treeOf(trees, t, i).class_label) << ' ' << exactNumber(p.x) << ' ' << exactNumber(p.y) << ' '
        << exactNumber(p.z) << ' ' << exactNumber(nodeRadius(t, i)) << ' ' << (root ? -1 : id[t.junction(t.parent[i])]) << '\n';
  }
}

void writeGraphml(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees) {
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<graphml xmlns=\"http://graphml.graphdrawing.org/xmlns\" "
         "xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
         "xsi:schemaLocation=\"http://graphml.graphdrawing.org/xmlns http://graphml.graphdrawing.org/xmlns/1.0/graphml.xsd\">\n"
         "  <key id=\"x\" for=\"node\" attr.name=\"x\" attr.type=\"double\"/>\n"
         "  <key id=\"y\" for=\"node\" attr.name=\"y\" attr.type=\"double\"/>\n"
         "  <key id=\"z\" for=\"node\" attr.name=\"z\" attr.type=\"double\"/>\n"
         "  <key id=\"type\" for=\"node\" attr.name=\"type\" attr.type=\"string\"/>\n"
         "  <key id=\"node_radius\" for=\"node\" attr.name=\"radius\" attr.type=\"double\"/>\n"
         "  <key id=\"node_tree\" for=\"node\" attr.name=\"tree\" attr.type=\"string\"/>\n"
         "  <key id=\"node_kind\" for=\"node\" attr.name=\"kind\" attr.type=\"string\"/>\n"
         "  <key id=\"length\" for=\"edge\" attr.name=\"length\" attr.type=\"double\"/>\n"
         "  <key id=\"radius\" for=\"edge\" attr.name=\"radius\" attr.type=\"double\"/>\n"
         "  <key id=\"flow\" for=\"edge\" attr.name=\"flow\" attr.type=\"double\"/>\n"
         "  <key id=\"tree\" for=\"edge\" attr.name=\"tree\" attr.type=\"string\"/>\n"
         "  <key id=\"kind\" for=\"edge\" attr.name=\"kind\" attr.type=\"string\"/>\n";
  const bool staged = t.hasStages(), tapered = t.hasTapers() || t.hasWalls();
  if (tapered)
    out << "  <key id=\"radius_start\" for=\"edge\" attr.name=\"radius_start\" attr.type=\"double\"/>\n"
           "  <key id=\"wall_start\" for=\"edge\" attr.name=\"wall_start\" attr.type=\"double\"/>\n"
           "  <key id=\"wall\" for=\"edge\" attr.name=\"wall\" attr.type=\"double\"/>\n";
  if (staged)
    out << "  <key id=\"stage\" for=\"edge\" attr.name=\"stage\" attr.type=\"int\"/>\n"
           "  <key id=\"role\" for=\"edge\" attr.name=\"role\" attr.type=\"string\"/>\n"
           "  <key id=\"branching\" for=\"edge\" attr.name=\"branching\" attr.type=\"string\"/>\n";
  out << "  <graph id=\"tree\" edgedefault=\"directed\">\n";
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) continue;
    const Vec3& p = t.position[i];
    const TreeInfo& tr = treeOf(trees, t, i);
    out << "    <node id=\"n" << i << "\"><data key=\"x\">" << exactNumber(p.x) << "</data><data key=\"y\">" << exactNumber(p.y)
        << "</data><data key=\"z\">" << exactNumber(p.z) << "</data><data key=\"type\">" << nodeTypeName(t.graphType(i))
        << "</data><data key=\"node_radius\">" << exactNumber(nodeRadius(t, i)) << "</data><data key=\"node_tree\">" << tr.id
        << "</data><data key=\"node_kind\">" << tr.kind << "</data></node>\n";
  }
  for (std::int32_t i = 1; i < t.nodeCount(); ++i) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    const TreeInfo& tr = treeOf(trees, t, i);
    out << "    <edge id=\"e" << i << "\" source=\"n" << t.junction(t.parent[i]) << "\" target=\"n" << i << "\"><data key=\"length\">"
        << exactNumber(t.length[i]) << "</data><data key=\"radius\">" << exactNumber(t.radius[i]) << "</data><data key=\"flow\">"
        << exactNumber(t.flow[i]) << "</data><data key=\"tree\">" << tr.id << "</data><data key=\"kind\">" << tr.kind << "</data>";
    if (staged)
      out << "<data key=\"stage\">" << t.stage[i] << "</data><data key=\"role\">" << roleName(t.role[i]) << "</data><data key=\"branching\">"
          << branchingName(t.branching[i]) << "</data>";
    if (tapered)
      out << "<data key=\"radius_start\">" << exactNumber(t.startRadius(i)) << "</data><data key=\"wall_start\">" << exactNumber(t.wall_start[i])
          << "</data><data key=\"wall\">" << exactNumber(t.wall[i]) << "</data>";
    out << "</edge>\n";
  }
  out << "  </graph>\n</graphml>\n";
}

}  // namespace angiosynth
