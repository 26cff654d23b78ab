#include "io/graph_writers.hpp"

#include <cstdio>

#include "core/format.hpp"
#include "core/vessel_roles.hpp"

namespace angiosynth {
namespace {

std::string sig6(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string floatAttr(const char* name, double v) {
  return std::string("      <attr name=\"") + name + "\"><float>" + exactNumber(v) + "</float></attr>\n";
}

std::string tupAttr(const char* name, const Vec3& p) {
  return std::string("      <attr name=\"") + name + "\"><tup><float>" + exactNumber(p.x) + "</float><float>" + exactNumber(p.y) + "</float><float>" +
         exactNumber(p.z) + "</float></tup></attr>\n";
}

std::string stringAttr(const char* name, const std::string& v) {
  return std::string("      <attr name=\"") + name + "\"><string>" + v + "</string></attr>\n";
}

// Staged growth: the stage (from 0, in [[stage]] order), role and branching of segment i.
std::string stageAttrs(const VascularTree& t, std::int32_t i, bool staged) {
  if (!staged) return "";
  return "      <attr name=\"stage\"><int>" + std::to_string(t.stage[i]) + "</int></attr>\n" + stringAttr("role", roleName(t.role[i])) +
         stringAttr("branching", branchingName(t.branching[i]));
}

// Tapered vessels (Lázaro 2011): the radius at the proximal end and the wall at both ends.
std::string taperAttrs(const VascularTree& t, std::int32_t i, bool tapered) {
  if (!tapered) return "";
  return floatAttr("radius_start", t.startRadius(i)) + floatAttr("wall_start", t.wall_start[i]) + floatAttr("wall", t.wall[i]);
}

}  // namespace

const TreeInfo& treeOf(const std::vector<TreeInfo>& trees, const VascularTree& t, std::int32_t node) {
  return trees.at(t.tree.empty() ? 0 : static_cast<std::size_t>(t.tree[node]));
}

void writeGxl(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees, const GraphFrame& f, const std::string& graph_id) {
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<!DOCTYPE gxl SYSTEM \"http://www.gupro.de/GXL/gxl-1.0.dtd\">\n"
         "<gxl xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n"
      << "  <graph id=\"" << graph_id << "\" edgeids=\"true\" edgemode=\"directed\" hypergraph=\"false\">\n";
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) continue;
    out << "    <node id=\"n" << i << "\">\n"
        << "      <attr name=\"type\"><string>" << nodeTypeName(t.graphType(i)) << "</string></attr>\n"
        << stringAttr("tree", treeOf(trees, t, i).id) << stringAttr("kind", treeOf(trees, t, i).kind) << tupAttr("position", t.position[i])
        << tupAttr("position_voxel", t.position[i] / f.voxel_mm) << "    </node>\n";
  }
  const bool tapered = t.hasTapers() || t.hasWalls(), staged = t.hasStages();
  for (auto i : t.topDownOrder()) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    out << "    <edge id=\"e" << i << "\" from=\"n" << t.junction(t.parent[i]) << "\" to=\"n" << i << "\">\n"
        << stringAttr("tree", treeOf(trees, t, i).id) << stringAttr("kind", treeOf(trees, t, i).kind) << floatAttr("radius", t.radius[i])
        << floatAttr("length", t.length[i]) << floatAttr("flow", t.flow[i]) << floatAttr("pressure_proximal", t.pressure[t.parent[i]])
        << floatAttr("pressure_distal", t.pressure[i]) << stageAttrs(t, i, staged) << taperAttrs(t, i, tapered) << "    </edge>\n";
  }
  out << "  </graph>\n</gxl>\n";
}

void writeVascuSynthGxl(std::ostream& out, const VascularTree& t, const GraphFrame& f, const std::string& graph_id) {
  static const char* kTypes[] = {" root node ", " bifurication ", " terminal node "};
  const double len = f.vs_units.mm_per_length;
  out << "<gxl><graph id=\"" << graph_id << "\" edgeids=\" true\" edgemode=\" directed\" hypergraph=\" false\">\n";
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) continue;
    const Vec3 v = t.position[i] / f.voxel_mm;
    const auto type = t.graphType(i);  // VascuSynth's three types: a junction is its bifurcation
    out << "  <node id=\"n" << i << "\">\n"
        << "    <attr name=\" nodeType\"><string>"
        << kTypes[type == NodeType::Root       ? 0
                  : type == NodeType::Terminal ? 2
                                               : 1]
        << "</string></attr>\n"
        << "    <attr name=\" position\"><tup><float>" << sig6(v.x) << "</float><float>" << sig6(v.y) << "</float><float>" << sig6(v.z)
        << "</float></tup></attr>\n"
        << "  </node>\n";
  }
  for (auto i : t.topDownOrder()) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    out << "  <edge id=\"e" << i << "\" to=\"n" << i << "\" from=\"n" << t.junction(t.parent[i]) << "\">\n"
        << "    <attr name=\" flow\"><float>" << sig6(t.flow[i] / f.vs_units.mm3s_per_flow()) << "</float></attr>\n"
        << "    <attr name=\" radius\"><float>" << sig6(t.radius[i] / len) << "</float></attr>\n"
        << "  </edge>\n";
  }
  out << "</graph></gxl>\n";
}

void writeDot(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees, const GraphFrame& f) {
  out << "digraph tree {\n  // positions in mm; radius and length in mm, flow in mm^3/s, pressure in Pa\n";
  const bool staged = t.hasStages(), tapered = t.hasTapers() || t.hasWalls();
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isLink(i)) continue;
    const Vec3& p = t.position[i];
    out << "  n" << i << " [type=" << nodeTypeName(t.graphType(i)) << ", tree=\"" << treeOf(trees, t, i).id << "\", kind=\""
        << treeOf(trees, t, i).kind << "\", position=\"" << exactNumber(p.x) << "," << exactNumber(p.y) << "," << exactNumber(p.z) << "\"];\n";
  }
  for (auto i : t.topDownOrder()) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    out << "  n" << t.junction(t.parent[i]) << " -> n" << i << " [tree=\"" << treeOf(trees, t, i).id << "\", kind=\"" << treeOf(trees, t, i).kind
        << "\", radius=" << exactNumber(t.radius[i]) << ", length=" << exactNumber(t.length[i]) << ", flow=" << exactNumber(t.flow[i])
        << ", pressure=" << exactNumber(t.pressure[i]);
    if (staged) out << ", stage=" << t.stage[i] << ", role=" << roleName(t.role[i]) << ", branching=" << branchingName(t.branching[i]);
    if (tapered)
      out << ", radius_start=" << exactNumber(t.startRadius(i)) << ", wall_start=" << exactNumber(t.wall_start[i])
          << ", wall=" << exactNumber(t.wall[i]);
    out << "];\n";
  }
  out << "}\n";
}

}  // namespace angiosynth
