#include "io/network_files.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/memory.hpp"
#include "core/physical_ranges.hpp"
#include "core/vessel_roles.hpp"
#include "io/network_rows.hpp"
#include "settings/param_checks.hpp"

namespace angiosynth {
namespace network_detail {
namespace {

struct Line {
  int number;
  std::vector<std::string> tokens;
};

std::vector<Line> tokenLines(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), 0, "cannot read the network file");
  std::vector<Line> out;
  std::string text;
  for (int n = 1; std::getline(in, text); ++n) {
    if (const auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
    std::istringstream ss(text);
    Line l{n, {}};
    for (std::string t; ss >> t;) l.tokens.push_back(t);
    if (!l.tokens.empty()) out.push_back(std::move(l));
  }
  return out;
}

double number(const std::string& file, const Line& l, std::size_t k, const char* what) {
  if (k >= l.tokens.size()) throw InputError(file, l.number, std::string("missing ") + what);
  try {
    std::size_t used = 0;
    const double v = std::stod(l.tokens[k], &used);
    if (used == l.tokens[k].size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {}
  throw InputError(file, l.number, std::string(what) + " '" + l.tokens[k] + "' is not a finite number");
}

long long whole(const std::string& file, const Line& l, std::size_t k, const char* what) {
  const double v = number(file, l, k, what);
  if (v != std::floor(v) || std::abs(v) > 1e15) throw InputError(file, l.number, std::string(what) + " '" + l.tokens[k] + "' is not an integer");
  return static_cast<long long>(v);
}

}  // namespace

ExistingNetwork assemble(const std::string& file, const std::vector<Row>& rows, bool swc, double unit_mm) {
  std::map<std::string, std::size_t> at;
  for (std::size_t k = 0; k < rows.size(); ++k)
    if (!at.emplace(rows[k].id, k).second) throw InputError(file, rows[k].line, "id " + rows[k].id + " is defined twice");
  for (const auto& r : rows) {
    const std::string of = (swc ? "sample " : "vessel ") + r.id;
    if (!swc)
      for (int a = 0; a < 3; ++a) physical::checkCoordinate(r.prox[a] * unit_mm, file, r.line, of + ": start coordinate");
    for (int a = 0; a < 3; ++a) physical::checkCoordinate(r.dist[a] * unit_mm, file, r.line, of + (swc ? ": coordinate" : ": end coordinate"));
    physical::checkRadius(r.radius * unit_mm, file, r.line, of + ": its radius", true);
    if (r.radius_start != -1) physical::checkRadius(r.radius_start * unit_mm, file, r.line, of + ": its radius at the start", true);
    for (const double w : {r.wall_start, r.wall})
      if (!(w * unit_mm >= 0 && w * unit_mm <= physical::kMaxRadiusMm))
        throw InputError(
            file, r.line,
            of + ": a wall thickness of " + show(w * unit_mm) + " mm is out of range; allowed: 0 (none) to " + show(physical::kMaxRadiusMm) + " mm");
  }
  std::vector<std::vector<std::size_t>> kids(rows.size());
  std::vector<std::size_t> roots;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (rows[k].parent.empty()) {
      roots.push_back(k);
      continue;
    }
    const auto p = at.find(rows[k].parent);
    if (p == at.end()) throw InputError(file, rows[k].line, "parent " + rows[k].parent + " of " + rows[k].id + " is not defined");
    kids[p->second].push_back(k);
  }
  if (roots.empty()) throw InputError(file, rows.empty() ? 0 : rows.front().line, "no root (parent -1): the network is a cycle or empty");
  ExistingNetwork net;
  auto& t = net.tree;
  const auto note = [&](std::int32_t node, const Row& r) {
    net.ids.push_back(r.id);
    net.lines.push_back(r.line);
    t.radius[node] = r.radius * unit_mm;
    // A tapered vessel keeps its proximal radius (a cylinder's equals its radius: none).
    if (r.radius_start >= 0 && r.radius_start != r.radius) t.radius_start[node] = r.radius_start * unit_mm;
    t.wall_start[node] = r.wall_start * unit_mm;
    t.wall[node] = r.wall * unit_mm;
    t.outflow[node] = r.outflow;
    t.stage[node] = r.stage;
    t.role[node] = r.role;
    t.branching[node] = r.branching;
  };
  std::vector<std::int32_t> node(rows.size(), -1);
  std::size_t placed = 0;
  for (std::size_t tr = 0; tr < roots.size(); ++tr) {
    const auto& r = rows[roots[tr]];
    net.tree_names.push_back(r.tree_name);
    net.tree_kinds.push_back(r.kind);
    const auto root = t.addNode(swc ? r.dist * unit_mm : r.prox * unit_mm, -1, std::int32_t(tr));
    if (swc) {
      note(root, r);
      node[roots[tr]] = root;
    } else {
      net.ids.push_back("");
      net.lines.push_back(r.line);
      node[roots[tr]] = t.addNode(r.dist * unit_mm, root);
      note(node[roots[tr]], r);
    }
    ++placed;
    std::vector<std::size_t> queue{roots[tr]};
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const auto k = queue[q];
      // An N-ary junction (m ≥ 3 children) becomes a chain of m − 2 links at its point: child j
      // (j ≥ 1) hangs from a new link while two or more children are left.
      std::int32_t from = node[k];
      for (std::size_t j = 0; j < kids[k].size(); ++j) {
        const auto c = kids[k][j];
        if (j >= 1 && kids[k].size() - j >= 2) {
          const auto link = t.addNode(t.position[node[k]], from);
          net.ids.push_back("");
          net.lines.push_back(rows[k].line);
          t.radius[link] = t.radius[node[k]];
          t.stage[link] = rows[k].stage;
          t.role[link] = rows[k].role;
          t.branching[link] = std::uint8_t(Branching::None);
          from = link;
        }
        const auto& row = rows[c];
        if (!swc) {
          const double tol = 1e-9 * (1 + norm(rows[k].dist));
          if (distance(row.prox, rows[k].dist) > tol)
            throw InputError(file, row.line,
                             "vessel " + row.id + " starts at " + show3(row.prox) + ", not where its parent " + rows[k].id + " ends (" +
                                 show3(rows[k].dist) + ")");
        }
        node[c] = t.addNode(row.dist * unit_mm, from);
        note(node[c], row);
        ++placed;
        queue.push_back(c);
      }
    }
  }
  if (placed != rows.size())
    for (std::size_t k = 0; k < rows.size(); ++k)
      if (node[k] < 0) throw InputError(file, rows[k].line, rows[k].id + " is not connected to a root: its parents form a cycle");
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (!t.isRoot(i) && !(t.length[i] > 0) && !net.ids[i].empty()) throw InputError(file, net.lines[i], net.ids[i] + " has zero length");
  if (t.segmentCount() == 0) throw InputError(file, rows.front().line, "no vessel; allowed: a network of at least one vessel (two connected nodes)");
  return net;
}

std::uint8_t branchingFromVita(const std::string& file, int line, long long code) {
  switch (code) {
    case 0: return std::uint8_t(Branching::None);
    case 1: return std::uint8_t(Branching::Fixed);
    case 2: return std::uint8_t(Branching::Versatile);
    case 3: return std::uint8_t(Branching::Distal);
    default:
      throw InputError(
          file, line,
          "branching mode " + std::to_string(code) + "; allowed: 0 (none), 1 (fixed), 2 (versatile), 3 (distal); 4 (hotspots) is not supported");
  }
}

std::uint8_t roleFromVita(const std::string& file, int line, long long code) {
  switch (code) {
    case 0: return std::uint8_t(VesselRole::Distribution);
    case 1: return std::uint8_t(VesselRole::Perforator);
    case 2: return std::uint8_t(VesselRole::Transport);
    default: throw InputError(file, line, "vessel function " + std::to_string(code) + "; allowed: 0 (distribution), 1 (perforator), 2 (transport)");
  }
}

std::uint8_t roleNamed(const std::string& file, int line, const std::string& name) {
  for (auto r : {VesselRole::Distribution, VesselRole::Transport, VesselRole::Perforator})
    if (name == roleName(std::uint8_t(r))) return std::uint8_t(r);
  if (name.empty()) return 0;
  throw InputError(file, line, "role '" + name + "'; allowed: distribution, transport, perforator");
}

std::uint8_t branchingNamed(const std::string& file, int line, const std::string& name) {
  for (auto b : {Branching::Versatile, Branching::Fixed, Branching::Distal, Branching::None})
    if (name == branchingName(std::uint8_t(b))) return std::uint8_t(b);
  if (name.empty()) return 0;
  throw InputError(file, line, "branching '" + name + "'; allowed: versatile, fixed, distal, none");
}

std::vector<Row> rowsFromPoints(const std::string& file, const std::vector<Vec3>& points, std::vector<PointSegment> segments) {
  constexpr auto kNone = std::size_t(-1);
  std::vector<std::size_t> ending(points.size(), kNone), root_starts(points.size(), 0);
  for (std::size_t k = 0; k < segments.size(); ++k) {
    auto& s = segments[k];
    if (s.from >= points.size() || s.to >= points.size())
      throw InputError(file, s.row.line, "vessel " + s.row.id + " refers to a point that is not defined");
    if (s.from == s.to) throw InputError(file, s.row.line, "vessel " + s.row.id + " starts and ends at the same point");
    if (ending[s.to] != kNone)
      throw InputError(file, s.row.line,
                       "vessels " + segments[ending[s.to]].row.id + " and " + s.row.id + " both end at " + show3(points[s.to]) +
                           ": a node of a tree has one parent vessel (a cycle, or vessels that merge)");
    ending[s.to] = k;
  }
  std::vector<Row> rows;
  rows.reserve(segments.size());
  for (auto& s : segments) {
    s.row.prox = points[s.from];
    s.row.dist = points[s.to];
    if (ending[s.from] != kNone) {
      s.row.parent = segments[ending[s.from]].row.id;
    } else if (++root_starts[s.from] > 1) {
      throw InputError(file, s.row.line,
                       "vessel " + s.row.id + " starts at the root point " + show3(points[s.from]) +
                           ", which starts another vessel: a tree's root has one vessel");
    }
    rows.push_back(s.row);
  }
  return rows;
}

namespace {

ExistingNetwork readCco(const std::string& file, double unit_mm) {
  const auto lines = tokenLines(file);
  std::size_t k = 0;
  const auto find = [&](const char* tag) {
    for (std::size_t j = k; j < lines.size(); ++j)
      if (lines[j].tokens.front() == tag) return j;
    return lines.size();
  };
  ExistingNetwork head;
  if (const auto tree = find("*Tree"); tree < lines.size()) {
    // The header may share the tag's line or follow it.
    std::vector<std::string> values(lines[tree].tokens.begin() + 1, lines[tree].tokens.end());
    int line = lines[tree].number;
    for (std::size_t j = tree + 1; values.size() < 11 && j < lines.size() && lines[j].tokens.front()[0] != '*'; ++j) {
      values.insert(values.end(), lines[j].tokens.begin(), lines[j].tokens.end());
      line = lines[j].number;
    }
    const Line h{line, values};
    head.flow = number(file, h, 3, "inflow (qProx)");
    head.reference_pressure = number(file, h, 7, "reference pressure");
    head.root_radius = number(file, h, 9, "root radius") * unit_mm;
  }
  k = find("*Vessels");
  if (k + 1 >= lines.size()) throw InputError(file, 0, "no *Vessels section: not a VItA .cco tree");
  const auto count = whole(file, lines[k + 1], 0, "vessel count");
  if (count < 1 || std::size_t(count) + k + 2 > lines.size())
    throw InputError(file, lines[k + 1].number, "vessel count " + std::to_string(count) + " does not match the rows that follow");
  std::vector<Row> rows;
  std::map<std::string, std::size_t> at;
  for (long long v = 0; v < count; ++v) {
    const auto& l = lines[k + 2 + std::size_t(v)];
    if (l.tokens.size() != 20 && l.tokens.size() != 21)
      throw InputError(file, l.number,
                       "a vessel row has 20 or 21 columns (id, proximal and distal points, ..., stage), not " + std::to_string(l.tokens.size()));
    Row r;
    r.line = l.number;
    r.id = std::to_string(whole(file, l, 0, "vessel id"));
    r.prox = Vec3(number(file, l, 1, "x"), number(file, l, 2, "y"), number(file, l, 3, "z"));
    r.dist = Vec3(number(file, l, 4, "x"), number(file, l, 5, "y"), number(file, l, 6, "z"));
    r.outflow = number(file, l, 10, "reserved outflow fraction");
    if (!(r.outflow >= 0 && r.outflow < 1)) throw InputError(file, l.number, "reserved outflow fraction must lie in [0, 1)");
    r.branching = branchingFromVita(file, l.number, whole(file, l, 11, "branching mode"));
    r.radius = number(file, l, 12, "radius");
    r.role = roleFromVita(file, l.number, whole(file, l, 17, "vessel function"));
    if (l.tokens.size() == 21) {
      const auto st = whole(file, l, 20, "stage");
      if (st < -1 || st > 30000) throw InputError(file, l.number, "stage must lie in [-1, 30000]");
      r.stage = std::int16_t(st);
    }
    at[r.id] = rows.size();
    rows.push_back(r);
  }
  k = find("*Connectivity");
  if (k >= lines.size()) throw InputError(file, 0, "no *Connectivity section");
  std::vector<char> seen(rows.size(), 0);
  std::vector<std::vector<std::string>> listed(rows.size());
  for (std::size_t j = k + 1; j < lines.size() && lines[j].tokens.front()[0] != '*'; ++j) {
    const auto& l = lines[j];
    const auto id = std::to_string(whole(file, l, 0, "vessel id"));
    const auto it = at.find(id);
    if (it == at.end()) throw InputError(file, l.number, "vessel " + id + " is not in *Vessels");
    if (seen[it->second]++) throw InputError(file, l.number, "vessel " + id + " is connected twice");
    const auto parent = whole(file, l, 1, "parent id");
    if (parent != -1) rows[it->second].parent = std::to_string(parent);
    for (std::size_t c = 2; c < l.tokens.size(); ++c) listed[it->second].push_back(std::to_string(whole(file, l, c, "child id")));
  }
  for (std::size_t r = 0; r < rows.size(); ++r)
    if (!seen[r]) throw InputError(file, rows[r].line, "vessel " + rows[r].id + " has no *Connectivity row");
  // The children lists must agree with the parents.
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (const auto& c : listed[r]) {
      const auto it = at.find(c);
      if (it == at.end() || rows[it->second].parent != rows[r].id)
        throw InputError(file, rows[r].line, "vessel " + rows[r].id + " lists child " + c + ", whose parent is not " + rows[r].id);
    }
  auto net = assemble(file, rows, false, unit_mm);
  net.flow = head.flow;
  net.reference_pressure = head.reference_pressure;
  net.root_radius = head.root_radius;
  return net;
}

ExistingNetwork readSwc(const std::string& file, double unit_mm) {
  std::vector<Row> rows;
  for (const auto& l : tokenLines(file)) {
    if (l.tokens.size() < 7) throw InputError(file, l.number, "an SWC row has 7 columns: id type x y z radius parent");
    Row r;
    r.line = l.number;
    r.id = std::to_string(whole(file, l, 0, "sample id"));
    r.dist = Vec3(number(file, l, 2, "x"), number(file, l, 3, "y"), number(file, l, 4, "z"));
    r.radius = number(file, l, 5, "radius");
    const auto parent = whole(file, l, 6, "parent id");
    if (parent != -1) r.parent = std::to_string(parent);
    rows.push_back(r);
  }
  return assemble(file, rows, true, unit_mm);
}

int vitaBranching(std::uint8_t b) {
  switch (Branching(b)) {
    case Branching::None: return 0;
    case Branching::Fixed: return 1;
    case Branching::Distal: return 3;
    default: return 2;
  }
}

int vitaFunction(std::uint8_t r) {
  switch (VesselRole(r)) {
    case VesselRole::Perforator: return 1;
    case VesselRole::Transport: return 2;
    default: return 0;
  }
}

}  // namespace
}  // namespace network_detail

void refuseLargeJunctions(const ExistingNetwork& net, const std::string& file, const std::string& use) {
  const auto& t = net.tree;
  std::vector<std::int32_t> kids;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    // Only the first node of a junction: its links follow it (a bifurcation has none).
    if (t.isLink(i) || t.child1[i] < 0 || !(t.isLink(t.child0[i]) || t.isLink(t.child1[i]))) continue;
    kids.clear();
    t.junctionChildren(i, kids);
    if (kids.size() > std::size_t(physical::kMaxJunctionChildren))
      throw InputError(file, net.lines[std::size_t(i)],
                       "node " + (net.ids[std::size_t(i)].empty() ? std::to_string(i) : net.ids[std::size_t(i)]) + " has " +
                           std::to_string(kids.size()) + " children; " + use + " at most " + std::to_string(physical::kMaxJunctionChildren) +
                           " (a vascular junction has two to four; a node of many is a skeletonisation artefact: split it)");
  }
}

ExistingNetwork readNetwork(const std::filesystem::path& file, double unit_mm, std::uint64_t memory_limit) {
  auto ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  using namespace network_detail;
  if (memory_limit == 0) memory_limit = defaultMemoryLimitBytes();
  if (ext != ".vtp") {
    // A text row of a vessel takes 16 bytes or more (a CSV pair: both files).
    std::error_code ec;
    std::uint64_t bytes = std::filesystem::file_size(file, ec);
    if (ext == ".csv") {
      const std::string name = file.filename().string();
      for (const auto& [from, to] : {std::pair{"nodes", "edges"}, {"edges", "nodes"}})
        if (const auto at = name.rfind(from); at != std::string::npos) {
          bytes += std::filesystem::file_size(file.parent_path() / (name.substr(0, at) + to + name.substr(at + 5)), ec);
          break;
        }
    }
    const std::uint64_t need = (bytes / 16 + 1) * kNetworkBytesPerVessel;
    if (!ec && need > memory_limit)
      throw InputError(file.string(), 0,
                       "a network file of " + formatBytes(bytes) + " needs up to " + formatBytes(need) + " to read, more than the limit of " +
                           formatBytes(memory_limit) + "; raise --memory-limit");
  }
  if (ext == ".cco") return readCco(file.string(), unit_mm);
  if (ext == ".swc") return readSwc(file.string(), unit_mm);
  if (ext == ".gxl") return readGxl(file.string(), unit_mm);
  if (ext == ".csv") return readCsv(file.string(), unit_mm);
  if (ext == ".vtp") return readVtp(file.string(), unit_mm, memory_limit);
  throw InputError(file.string(), 0, "unknown network format '" + ext + "'; allowed: .cco (VItA), .swc, .gxl, .csv (nodes and edges), .vtp");
}

void writeCco(std::ostream& out, const VascularTree& t, const std::vector<TreeInfo>& trees) {
  using namespace network_detail;
  (void)trees;
  const auto roots = t.roots();
  double terminal_pressure = 0;
  bool any = false;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (t.isTerminal(i) && !(t.outflow.size() > std::size_t(i) && t.outflow[i] > 0)) {
      terminal_pressure = any ? std::min(terminal_pressure, t.pressure[i]) : t.pressure[i];
      any = true;
    }
  const auto root = roots.empty() ? -1 : roots.front();
  const auto seg = root >= 0 ? t.child0[root] : -1;
  out << "# angiosynth vascular tree in VItA's .cco layout; mm, Pa, mm^3/s\n*Tree\n";
  if (seg > 0) {
    const Vec3& p = t.position[root];
    out << exactNumber(p.x) << ' ' << exactNumber(p.y) << ' ' << exactNumber(p.z) << ' ' << exactNumber(t.flow[seg]) << " 0 "
        << exactNumber(t.pressure[root] - terminal_pressure) << ' ' << t.totalTerminals() << ' ' << exactNumber(terminal_pressure) << ' '
        << t.nodeCount() << ' ' << exactNumber(t.radius[seg]) << " 1e-06\n";
  }
  // Links are not vessels: an N-ary junction's vessels list each other as parent and children.
  std::int32_t links = 0;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) links += t.isLink(i);
  out << "\n*Vessels\n" << t.nodeCount() - std::int32_t(roots.size()) - links << '\n';
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    const Vec3 &a = t.position[t.parent[i]], &b = t.position[i];
    const double dp = t.pressure[t.parent[i]] - t.pressure[i];
    out << i << ' ' << exactNumber(a.x) << ' ' << exactNumber(a.y) << ' ' << exactNumber(a.z) << ' ' << exactNumber(b.x) << ' ' << exactNumber(b.y)
        << ' ' << exactNumber(b.z) << " 0 0 0 " << exactNumber(i < std::int32_t(t.outflow.size()) ? t.outflow[i] : 0.0) << ' '
        << vitaBranching(t.branching[i]) << ' ' << exactNumber(t.radius[i]) << ' ' << exactNumber(t.flow[i] > 0 ? dp / t.flow[i] : 0.0) << " 0 0 "
        << exactNumber(t.pressure[t.parent[i]]) << ' ' << vitaFunction(t.role[i]) << " 0 0 " << t.stage[i] << '\n';
  }
  out << "\n*Connectivity\n";
  std::vector<std::int32_t> kids;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    if (t.isRoot(i) || t.isLink(i)) continue;
    const auto from = t.junction(t.parent[i]);
    out << i << ' ' << (t.isRoot(from) ? -1 : from);
    kids.clear();
    t.junctionChildren(i, kids);
    for (auto c : kids) out << ' ' << c;
    out << '\n';
  }
}

}  // namespace angiosynth
