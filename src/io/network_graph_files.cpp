// Initial networks from the graphs angiosynth writes: tree.gxl, and the nodes.csv / edges.csv
// pair. Attributes the file lacks (stage, role, branching) are left unset for [initial]'s defaults.
#include <tinyxml2.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "io/network_rows.hpp"

namespace angiosynth::network_detail {
namespace {

double finite(const std::string& file, int line, const char* text, const std::string& what) {
  try {
    std::size_t used = 0;
    const std::string s = text ? text : "";
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {}
  throw InputError(file, line, what + " '" + (text ? text : "") + "' is not a finite number");
}

// The value element of a GXL <attr name="...">, or null.
const tinyxml2::XMLElement* gxlAttr(const tinyxml2::XMLElement* owner, const char* name) {
  for (auto* a = owner->FirstChildElement("attr"); a; a = a->NextSiblingElement("attr"))
    if (const char* n = a->Attribute("name"); n && std::string(n) == name) return a->FirstChildElement();
  return nullptr;
}

}  // namespace

ExistingNetwork readGxl(const std::string& file, double unit_mm) {
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(file.c_str()) != tinyxml2::XML_SUCCESS)
    throw InputError(file, doc.ErrorLineNum(), std::string("not readable as XML: ") + doc.ErrorStr());
  const auto* graph = doc.FirstChildElement("gxl") ? doc.FirstChildElement("gxl")->FirstChildElement("graph") : nullptr;
  if (!graph) throw InputError(file, 1, "no <gxl><graph>: not a GXL file");
  std::map<std::string, std::size_t> point_of;
  std::vector<Vec3> points;
  for (auto* n = graph->FirstChildElement("node"); n; n = n->NextSiblingElement("node")) {
    const int line = n->GetLineNum();
    const char* id = n->Attribute("id");
    if (!id) throw InputError(file, line, "a node without an id");
    const auto* tup = gxlAttr(n, "position");
    if (!tup || std::string(tup->Name()) != "tup")
      throw InputError(file, line,
                       std::string("node ") + id +
                           " has no attribute 'position' (a tup of three floats in mm, as angiosynth writes; VascuSynth's "
                           "' position' in voxels is not read: convert it to SWC)");
    double c[3];
    const auto* f = tup->FirstChildElement("float");
    for (int a = 0; a < 3; ++a, f = f ? f->NextSiblingElement("float") : nullptr) {
      if (!f) throw InputError(file, line, std::string("node ") + id + ": position needs three floats");
      c[a] = finite(file, f->GetLineNum(), f->GetText(), "coordinate");
    }
    if (!point_of.emplace(id, points.size()).second) throw InputError(file, line, std::string("node ") + id + " is defined twice");
    points.emplace_back(c[0], c[1], c[2]);
  }
  std::vector<PointSegment> segments;
  for (auto* e = graph->FirstChildElement("edge"); e; e = e->NextSiblingElement("edge")) {
    PointSegment s;
    s.row.line = e->GetLineNum();
    const char *from = e->Attribute("from"), *to = e->Attribute("to"), *id = e->Attribute("id");
    if (!from || !to) throw InputError(file, s.row.line, "an edge needs from and to");
    s.row.id = id ? id : std::string(from) + "-" + to;
    for (const auto& [name, at] : {std::pair{from, &s.from}, {to, &s.to}}) {
      const auto p = point_of.find(name);
      if (p == point_of.end()) throw InputError(file, s.row.line, "edge " + s.row.id + " refers to node " + name + ", which is not defined");
      *at = p->second;
    }
    const auto* radius = gxlAttr(e, "radius");
    if (!radius) throw InputError(file, s.row.line, "edge " + s.row.id + " has no 'radius' attribute (mm)");
    s.row.radius = finite(file, radius->GetLineNum(), radius->GetText(), "radius");
    // A tapered vessel and its wall, as angiosynth writes them.
    for (const auto& [name, to] : {std::pair{"radius_start", &s.row.radius_start}, {"wall_start", &s.row.wall_start}, {"wall", &s.row.wall}})
      if (const auto* a = gxlAttr(e, name)) *to = finite(file, a->GetLineNum(), a->GetText(), name);
    if (const auto* st = gxlAttr(e, "stage")) {
      const double v = finite(file, st->GetLineNum(), st->GetText(), "stage");
      if (v != std::floor(v) || v < -1 || v > 30000) throw InputError(file, st->GetLineNum(), "stage must be an integer in [-1, 30000]");
      s.row.stage = std::int16_t(v);
    }
    if (const auto* r = gxlAttr(e, "role")) s.row.role = roleNamed(file, r->GetLineNum(), r->GetText() ? r->GetText() : "");
    if (const auto* b = gxlAttr(e, "branching")) s.row.branching = branchingNamed(file, b->GetLineNum(), b->GetText() ? b->GetText() : "");
    segments.push_back(std::move(s));
  }
  if (segments.empty()) throw InputError(file, graph->GetLineNum(), "the graph has no edges");
  return assemble(file, rowsFromPoints(file, points, std::move(segments)), false, unit_mm);
}

namespace {

// A CSV table with a header row; columns are found by name.
struct Table {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::pair<int, std::vector<std::string>>> rows;  // line, cells

  explicit Table(const std::string& path) : file(path) {
    std::ifstream in(path);
    if (!in) throw InputError(path, 0, "cannot read the network file");
    std::string text;
    for (int n = 1; std::getline(in, text); ++n) {
      if (!text.empty() && text.back() == '\r') text.pop_back();
      if (text.empty()) continue;
      std::vector<std::string> cells;
      std::stringstream ss(text);
      for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
      if (header.empty()) {
        header = cells;
        continue;
      }
      if (cells.size() != header.size())
        throw InputError(path, n, std::to_string(cells.size()) + " cells; the header names " + std::to_string(header.size()));
      rows.emplace_back(n, std::move(cells));
    }
    if (header.empty()) throw InputError(path, 1, "empty: a header row is required");
  }
  // Index of the column `name`, or -1; `required` throws with the columns allowed.
  int column(const std::string& name, bool required) const {
    for (std::size_t k = 0; k < header.size(); ++k)
      if (header[k] == name) return int(k);
    if (required) throw InputError(file, 1, "no column '" + name + "' (angiosynth's nodes.csv and edges.csv)");
    return -1;
  }
};

}  // namespace

ExistingNetwork readCsv(const std::string& file, double unit_mm) {
  // Either file of the pair names the other: ...nodes....csv and ...edges....csv.
  const std::filesystem::path path(file);
  std::string name = path.filename().string();
  const auto swap = [&](const std::string& from, const std::string& to) {
    const auto at = name.rfind(from);
    if (at == std::string::npos) return std::string();
    return (path.parent_path() / (name.substr(0, at) + to + name.substr(at + from.size()))).string();
  };
  std::string nodes_file = file, edges_file = swap("nodes", "edges");
  if (edges_file.empty()) {
    edges_file = file;
    nodes_file = swap("edges", "nodes");
  }
  if (nodes_file.empty())
    throw InputError(file, 0, "a CSV network is a pair of files whose names contain 'nodes' and 'edges' (nodes.csv, edges.csv)");
  const Table nodes(nodes_file), edges(edges_file);
  const int id = nodes.column("id", true), x = nodes.column("pos_x", true), y = nodes.column("pos_y", true), z = nodes.column("pos_z", true);
  std::map<std::string, std::size_t> point_of;
  std::vector<Vec3> points;
  for (const auto& [line, c] : nodes.rows) {
    const auto& f = nodes.file;
    points.emplace_back(finite(f, line, c[x].c_str(), "pos_x"), finite(f, line, c[y].c_str(), "pos_y"), finite(f, line, c[z].c_str(), "pos_z"));
    if (!point_of.emplace(c[id], points.size() - 1).second) throw InputError(f, line, "node " + c[id] + " is defined twice");
  }
  const int eid = edges.column("id", false), from = edges.column("node1id", true), to = edges.column("node2id", true),
            radius = edges.column("radius", true), stage = edges.column("stage", false), role = edges.column("role", false),
            branching = edges.column("branching", false), radius_start = edges.column("radius_start", false),
            wall_start = edges.column("wall_start", false), wall = edges.column("wall", false), tree_column = edges.column("tree", false),
            kind_column = edges.column("kind", false);
  std::vector<PointSegment> segments;
  for (const auto& [line, c] : edges.rows) {
    const auto& f = edges.file;
    PointSegment s;
    s.row.line = line;
    s.row.id = eid >= 0 ? c[eid] : std::to_string(line);
    for (const auto& [col, at] : {std::pair{from, &s.from}, {to, &s.to}}) {
      const auto p = point_of.find(c[col]);
      if (p == point_of.end())
        throw InputError(f, line, "edge " + s.row.id + " refers to node " + c[col] + ", which " + nodes.file + " does not define");
      *at = p->second;
    }
    s.row.radius = finite(f, line, c[radius].c_str(), "radius");
    if (radius_start >= 0) s.row.radius_start = finite(f, line, c[radius_start].c_str(), "radius_start");
    if (wall_start >= 0) s.row.wall_start = finite(f, line, c[wall_start].c_str(), "wall_start");
    if (wall >= 0) s.row.wall = finite(f, line, c[wall].c_str(), "wall");
    if (stage >= 0) {
      const double v = finite(f, line, c[stage].c_str(), "stage");
      if (v != std::floor(v) || v < -1 || v > 30000) throw InputError(f, line, "stage must be an integer in [-1, 30000]");
      s.row.stage = std::int16_t(v);
    }
    if (role >= 0) s.row.role = roleNamed(f, line, c[role]);
    if (branching >= 0) s.row.branching = branchingNamed(f, line, c[branching]);
    if (tree_column >= 0) s.row.tree_name = c[tree_column];
    if (kind_column >= 0) s.row.kind = c[kind_column];
    segments.push_back(std::move(s));
  }
  if (segments.empty()) throw InputError(edges.file, 1, "no edges");
  return assemble(edges.file, rowsFromPoints(edges.file, points, std::move(segments)), false, unit_mm);
}

}  // namespace angiosynth::network_detail
