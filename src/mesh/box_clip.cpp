#include "mesh/box_clip.hpp"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Constrained_triangulation_face_base_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "mesh/plane_clip.hpp"

namespace angiosynth {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, K>;
using Fi = CGAL::Triangulation_face_base_with_info_2<int, K>;  // nesting depth: odd inside the section
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
// Loops of a closed surface's cut never cross: a crossing is an error, not a new vertex.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::No_constraint_intersection_tag>;

std::uint64_t directedKey(std::int32_t a, std::int32_t b) { return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b); }
double coord(const Vec3& p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }
void setCoord(Vec3& p, int axis, double v) { (axis == 0 ? p.x : axis == 1 ? p.y : p.z) = v; }

// Loop edges shorter than kShortLoopEdge of their ends' step collapse into their first vertex
// (both lie in the plane): a fan of needle triangles cut near its hub leaves cut points a few
// 10⁻⁵ mm apart, and the section between them would turn over in single precision. A collapse
// is made only where the two ends share no neighbour but the cut triangle's third vertex (the
// topology stays) and no triangle turns by more than 60°. Removed triangles get vertex −1.
// True if any was made.
bool collapseShortLoopEdges(const SurfaceMesh& m, std::vector<std::array<std::int32_t, 3>>& tris,
                            const std::vector<std::pair<std::int32_t, std::int32_t>>& loop_edges) {
  constexpr double kShortLoopEdge = 0.05;
  std::unordered_map<std::int32_t, std::vector<std::size_t>> at;  // loop vertex -> its triangles
  for (const auto& [a, b] : loop_edges) at[a], at[b];
  for (std::size_t k = 0; k < tris.size(); ++k)
    for (auto v : tris[k])
      if (auto it = at.find(v); it != at.end()) it->second.push_back(k);
  const auto stepOf = [&](std::int32_t v) { return m.vertex_step.empty() ? 0.0 : double(m.vertex_step[std::size_t(v)]); };
  std::unordered_map<std::int32_t, std::int32_t> merged;  // b -> a
  const auto alive = [&](std::int32_t v) { return !merged.count(v); };
  bool any = false;
  for (const auto& edge : loop_edges) {
    const auto a = edge.first, b = edge.second;  // (clang 14 captures no structured binding)
    if (!alive(a) || !alive(b)) continue;
    const Vec3& pa = m.vertices[std::size_t(a)];
    const Vec3& pb = m.vertices[std::size_t(b)];
    if (!(distance(pa, pb) < kShortLoopEdge * std::min(stepOf(a), stepOf(b)))) continue;
    auto& ta = at[a];
    auto& tb = at[b];
    std::size_t cut = tris.size();
    std::vector<std::int32_t> na, nb;
    for (auto k : ta)
      for (auto v : tris[k]) na.push_back(v);
    for (auto k : tb) {
      const auto& t = tris[k];
      if (t[0] < 0) continue;
      if (t[0] == a || t[1] == a || t[2] == a) cut = k;
      for (auto v : t) nb.push_back(v);
    }
    if (cut == tris.size()) continue;
    std::sort(na.begin(), na.end());
    std::sort(nb.begin(), nb.end());
    na.erase(std::unique(na.begin(), na.end()), na.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    std::vector<std::int32_t> common;
    std::set_intersection(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(common));
    if (common.size() != 3) continue;  // a, b and the cut triangle's third vertex
    bool ok = true;
    for (auto k : tb) {
      const auto& t = tris[k];
      if (k == cut || t[0] < 0) continue;
      const auto P = [&](std::int32_t q, bool after) -> const Vec3& { return after && q == b ? pa : m.vertices[std::size_t(q)]; };
      const Vec3 before = cross(P(t[1], false) - P(t[0], false), P(t[2], false) - P(t[0], false));
      const Vec3 now = cross(P(t[1], true) - P(t[0], true), P(t[2], true) - P(t[0], true));
      ok &= norm(now) > 0 && dot(before, now) > 0.5 * norm(before) * norm(now);
    }
    if (!ok) continue;
    tris[cut] = {-1, -1, -1};
    for (auto k : tb) {
      auto& t = tris[k];
      if (t[0] < 0) continue;
      for (auto& v : t)
        if (v == b) v = a;
      ta.push_back(k);
    }
    merged.emplace(b, a);
    any = true;
  }
  return any;
}

// Keeps the part of m where sigma·(x_axis − c) ≤ 0 and fills the section in the plane.
// Each vertex's signed distance to the side's plane (positive outside the box); vertices within
// `snap` of it go onto it, exactly.
std::vector<double> signedSides(SurfaceMesh& m, int axis, double c, double sigma, double snap) {
  std::vector<double> s(m.vertices.size());
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    s[v] = sigma * (coord(m.vertices[v], axis) - c);
    if (std::abs(s[v]) < snap) {  // onto the plane, exactly
      setCoord(m.vertices[v], axis, c);
      s[v] = 0;
    }
  }
  return s;
}

void moveSliverEndsOntoPlane(SurfaceMesh& m, std::vector<double>& s, int axis, double c) {
  // A cut within kSliver of an edge's end moves that end along the edge onto the plane instead
  // (it stays on the surface): a sliver there would turn over when a format rounds it to single
  // precision (STL). A move that would turn one of the vertex's triangles by more than 60° or
  // shrink it below a tenth is not made.
  constexpr double kSliver = 0.05;
  const std::size_t nt = m.triangles.size();
  const VertexTriangles incident(m);
  const auto normalOf = [&](const std::array<std::int32_t, 3>& t, std::int32_t v, const Vec3& at) {
    const auto P = [&](std::int32_t q) -> const Vec3& { return q == v ? at : m.vertices[std::size_t(q)]; };
    return cross(P(t[1]) - P(t[0]), P(t[2]) - P(t[0]));
  };
  // The vertex opposite edge (v, n) in v's triangle other than `skip`, or -1.
  const auto opposite = [&](std::int32_t v, std::int32_t n, std::int32_t skip) {
    for (const auto k : incident.of(v)) {
      if (k == skip) continue;
      const auto& t = m.triangles[std::size_t(k)];
      if (t[0] == n || t[1] == n || t[2] == n) return t[0] != v && t[0] != n ? t[0] : t[1] != v && t[1] != n ? t[1] : t[2];
    }
    return std::int32_t(-1);
  };
  const auto moveOnto = [&](std::int32_t v, Vec3 p) {
    setCoord(p, axis, c);
    const Vec3 here = m.vertices[std::size_t(v)];
    for (const auto k : incident.of(v)) {
      const auto& t = m.triangles[std::size_t(k)];
      const Vec3 before = normalOf(t, v, here), after = normalOf(t, v, p);
      const double nb = norm(before), na = norm(after);
      if (!(na > 0.1 * nb) || !(dot(before, after) > 0.5 * nb * na)) return;
      // Nor one that lays an edge in the plane between two kept triangles: the surface would
      // touch the section along it (an edge of four triangles).
      for (auto n : t) {
        if (n == v || s[std::size_t(n)] != 0) continue;
        std::int32_t x = -1;
        for (auto w : t)
          if (w != v && w != n) x = w;
        const auto y = opposite(v, n, k);
        if (y >= 0 && s[std::size_t(x)] < 0 && s[std::size_t(y)] < 0) return;
      }
    }
    m.vertices[std::size_t(v)] = p;
    s[std::size_t(v)] = 0;
  };
  for (std::size_t k = 0; k < nt; ++k)
    for (int i = 0; i < 3; ++i) {
      const auto a = m.triangles[k][std::size_t(i)], b = m.triangles[k][std::size_t((i + 1) % 3)];
      const double sa = s[std::size_t(a)], sb = s[std::size_t(b)];
      if (!((sa < 0 && sb > 0) || (sa > 0 && sb < 0))) continue;
      const double t = sa / (sa - sb);
      const Vec3 p = m.vertices[std::size_t(a)] + (m.vertices[std::size_t(b)] - m.vertices[std::size_t(a)]) * t;
      if (t < kSliver)
        moveOnto(a, p);
      else if (t > 1 - kSliver)
        moveOnto(b, p);
    }
}

// The wall clipped to the inside of the side: the triangles kept (cut ones as their inside
// pieces, cut points shared through their edge) with their trees and faces.
struct ClippedWall {
  std::vector<std::array<std::int32_t, 3>> tris;
  std::vector<std::int32_t> tree, faces;
};

ClippedWall clipWall(SurfaceMesh& m, std::vector<double>& s, int axis, double c, BoxClipReport& rep) {
  ClippedWall w;
  auto& tris = w.tris;
  auto& tree = w.tree;
  auto& faces = w.faces;
  // Cut points, shared through their edge.
  std::unordered_map<std::uint64_t, std::int32_t> cut_point;
  const auto pointOn = [&](std::int32_t a, std::int32_t b) {
    const auto key = directedKey(std::min(a, b), std::max(a, b));
    if (const auto it = cut_point.find(key); it != cut_point.end()) return it->second;
    const double sa = s[std::size_t(a)], sb = s[std::size_t(b)];
    Vec3 p = m.vertices[std::size_t(a)] + (m.vertices[std::size_t(b)] - m.vertices[std::size_t(a)]) * (sa / (sa - sb));
    setCoord(p, axis, c);
    const auto id = std::int32_t(m.vertices.size());
    m.vertices.push_back(p);
    if (!m.vertex_step.empty()) m.vertex_step.push_back(std::min(m.vertex_step[std::size_t(a)], m.vertex_step[std::size_t(b)]));
    s.push_back(0);
    cut_point.emplace(key, id);
    return id;
  };
  tris.reserve(m.triangles.size());
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    const auto tri = m.triangles[k];
    const double a = s[std::size_t(tri[0])], b = s[std::size_t(tri[1])], d = s[std::size_t(tri[2])];
    const auto keep = [&](const std::array<std::int32_t, 3>& t) {
      tris.push_back(t);
      tree.push_back(m.triangle_tree[k]);
      faces.push_back(m.triangle_face[k]);
    };
    if (a <= 0 && b <= 0 && d <= 0 && (a < 0 || b < 0 || d < 0)) {
      keep(tri);
      continue;
    }
    if (!(a < 0 || b < 0 || d < 0)) {  // outside, or in the plane (the section replaces it)
      ++rep.removed_triangles;
      continue;
    }
    clipTriangleToPlane(
        tri, [&](std::int32_t v) { return s[std::size_t(v)]; }, pointOn, [&](std::int32_t v) -> const Vec3& { return m.vertices[std::size_t(v)]; },
        [&](std::int32_t p, std::int32_t q, std::int32_t r) {
          keep({p, q, r});
        });
  }
  return w;
}

// The cut's loops: the directed edges in the plane that the kept wall uses once, with the tree of
// the triangle each belongs to.
struct SectionLoops {
  std::unordered_map<std::uint64_t, std::int32_t> edge_tree;
  std::vector<std::pair<std::int32_t, std::int32_t>> loop_edges;
};

SectionLoops findSectionLoops(SurfaceMesh& m, const std::vector<double>& s, ClippedWall& w) {
  SectionLoops l;
  auto& tris = w.tris;
  auto& tree = w.tree;
  auto& faces = w.faces;
  auto& edge_tree = l.edge_tree;
  auto& loop_edges = l.loop_edges;
  const auto findLoops = [&] {
    edge_tree.clear();
    loop_edges.clear();
    for (std::size_t k = 0; k < tris.size(); ++k)
      for (int i = 0; i < 3; ++i) {
        const auto a = tris[k][std::size_t(i)], b = tris[k][std::size_t((i + 1) % 3)];
        if (s[std::size_t(a)] == 0 && s[std::size_t(b)] == 0) edge_tree.emplace(directedKey(a, b), tree[k]);
      }
    for (const auto& [key, t] : edge_tree) {
      const auto a = std::int32_t(key >> 32), b = std::int32_t(key & 0xffffffffu);
      if (!edge_tree.count(directedKey(b, a))) loop_edges.emplace_back(a, b);
    }
    std::sort(loop_edges.begin(), loop_edges.end());  // the same triangulation whatever the hash order
  };
  findLoops();
  if (collapseShortLoopEdges(m, tris, loop_edges)) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < tris.size(); ++k)
      if (tris[k][0] >= 0) tris[n] = tris[k], tree[n] = tree[k], faces[n] = faces[k], ++n;
    tris.resize(n), tree.resize(n), faces.resize(n);
    findLoops();
  }
  return l;
}

std::vector<std::array<std::int32_t, 3>> triangulateSection(const SurfaceMesh& m,
                                                            const std::vector<std::pair<std::int32_t, std::int32_t>>& loop_edges, int axis,
                                                            double sigma, int side) {
  // The section: a constrained Delaunay triangulation of the loops, inside where it lies behind
  // an odd number of loops seen from outside them all.
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;  // e_u × e_w = e_axis
  Cdt cdt;
  std::unordered_map<std::int32_t, Cdt::Vertex_handle> handle;
  const auto vertex = [&](std::int32_t v) {
    if (const auto it = handle.find(v); it != handle.end()) return it->second;
    const Vec3& p = m.vertices[std::size_t(v)];
    const auto before = cdt.number_of_vertices();
    const auto h = cdt.insert(K::Point_2(coord(p, u), coord(p, w)));
    if (cdt.number_of_vertices() == before)
      throw std::runtime_error(std::string("clipping to the box: two vertices meet in the section of side ") + kBoxSideNames[side]);
    h->info() = v + 1;
    handle.emplace(v, h);
    return h;
  };
  for (const auto& [a, b] : loop_edges) vertex(a), vertex(b);
  try {
    for (const auto& [a, b] : loop_edges) cdt.insert_constraint(vertex(a), vertex(b));
  } catch (const std::exception&) {
    throw std::runtime_error(std::string("clipping to the box: the section's loops cross on side ") + kBoxSideNames[side]);
  }
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) f->info() = -1;
  std::vector<Cdt::Face_handle> stack{cdt.infinite_face()}, next;
  cdt.infinite_face()->info() = 0;
  for (int depth = 0; !stack.empty(); ++depth) {
    // Flood each depth through unconstrained edges; a constrained edge leads one deeper.
    while (!stack.empty()) {
      const auto f = stack.back();
      stack.pop_back();
      for (int i = 0; i < 3; ++i) {
        const auto g = f->neighbor(i);
        if (g->info() != -1) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          next.push_back(g);
        } else {
          g->info() = depth;
          stack.push_back(g);
        }
      }
    }
    for (auto g : next)
      if (g->info() == -1) g->info() = depth + 1, stack.push_back(g);
    next.clear();
  }
  // Inside faces, turned to face out of the box (along sigma·e_axis); each takes the tree of the
  // wall across its loop edges.
  std::unordered_map<std::uint64_t, char> loop_reverse;
  for (const auto& [a, b] : loop_edges) loop_reverse.emplace(directedKey(b, a), 0);
  std::vector<std::array<std::int32_t, 3>> section;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (f->info() % 2 == 0) continue;
    std::array<std::int32_t, 3> t{f->vertex(0)->info() - 1, f->vertex(1)->info() - 1, f->vertex(2)->info() - 1};
    if (t[0] < 0 || t[1] < 0 || t[2] < 0) throw std::runtime_error("clipping to the box: a section vertex is not on a loop");
    if (sigma < 0) std::swap(t[1], t[2]);
    section.push_back(t);
  }
  // Every loop edge is matched by one section edge running against it; else the loops did not
  // bound the section (an open surface, or loops that touch).
  std::size_t matched = 0;
  for (const auto& t : section)
    for (int i = 0; i < 3; ++i)
      if (auto it = loop_reverse.find(directedKey(t[std::size_t(i)], t[std::size_t((i + 1) % 3)])); it != loop_reverse.end() && !it->second++)
        ++matched;
  if (matched != loop_edges.size())
    throw std::runtime_error(std::string("clipping to the box: the section of side ") + kBoxSideNames[side] + " does not close the cut");
  return section;
}

// Each section triangle takes the tree of a loop edge of its connected patch.
std::vector<std::int32_t> sectionTrees(const std::vector<std::array<std::int32_t, 3>>& section,
                                       const std::unordered_map<std::uint64_t, std::int32_t>& edge_tree) {
  std::unordered_map<std::uint64_t, std::size_t> at_edge;
  for (std::size_t k = 0; k < section.size(); ++k)
    for (int i = 0; i < 3; ++i) at_edge.emplace(directedKey(section[k][std::size_t(i)], section[k][std::size_t((i + 1) % 3)]), k);
  std::vector<std::int32_t> section_tree(section.size(), -1);
  for (std::size_t k0 = 0; k0 < section.size(); ++k0) {
    if (section_tree[k0] >= 0) continue;
    std::vector<std::size_t> patch{k0}, todo{k0};
    section_tree[k0] = 0;
    std::int32_t found = -1;
    while (!todo.empty()) {
      const auto k = todo.back();
      todo.pop_back();
      for (int i = 0; i < 3; ++i) {
        const auto a = section[k][std::size_t(i)], b = section[k][std::size_t((i + 1) % 3)];
        if (const auto e = edge_tree.find(directedKey(b, a)); e != edge_tree.end() && found < 0) found = e->second;
        if (const auto o = at_edge.find(directedKey(b, a)); o != at_edge.end() && section_tree[o->second] < 0) {
          section_tree[o->second] = 0;
          patch.push_back(o->second);
          todo.push_back(o->second);
        }
      }
    }
    for (auto k : patch) section_tree[k] = std::max(found, 0);
  }
  return section_tree;
}

// The loops: components of the loop edges' graph.
std::int64_t countLoops(const std::vector<std::pair<std::int32_t, std::int32_t>>& loop_edges) {
  std::int64_t loops = 0;
  std::unordered_map<std::int32_t, std::int32_t> next_of;
  for (const auto& [a, b] : loop_edges) next_of.emplace(a, b);
  std::unordered_map<std::int32_t, char> seen;
  for (const auto& [a, b] : loop_edges) {
    if (seen.count(a)) continue;
    ++loops;
    for (std::int32_t v = a; !seen.count(v);) {
      seen.emplace(v, 1);
      const auto it = next_of.find(v);
      if (it == next_of.end()) break;
      v = it->second;
    }
  }
  return loops;
}

void clipSide(SurfaceMesh& m, int axis, double c, double sigma, double snap, std::int32_t face, BoxClipReport& rep, int side) {
  std::vector<double> s = signedSides(m, axis, c, sigma, snap);
  moveSliverEndsOntoPlane(m, s, axis, c);
  ClippedWall wall = clipWall(m, s, axis, c, rep);
  const SectionLoops loops = findSectionLoops(m, s, wall);
  m.triangles = std::move(wall.tris);
  m.triangle_tree = std::move(wall.tree);
  m.triangle_face = std::move(wall.faces);
  if (loops.loop_edges.empty()) return;
  const auto section = triangulateSection(m, loops.loop_edges, axis, sigma, side);
  const auto section_tree = sectionTrees(section, loops.edge_tree);
  for (std::size_t k = 0; k < section.size(); ++k) {
    const auto& t = section[k];
    m.triangles.push_back(t);
    m.triangle_tree.push_back(section_tree[k]);
    m.triangle_face.push_back(face);
    rep.section_area_mm2[std::size_t(side)] += triangleArea(m, t);
  }
  rep.section_triangles[std::size_t(side)] = std::int64_t(section.size());
  rep.section_loops[std::size_t(side)] += countLoops(loops.loop_edges);
}

}  // namespace

BoxClipReport clipToBox(SurfaceMesh& m, const Vec3& box_lo, const Vec3& box_hi, std::int32_t first_face) {
  BoxClipReport rep;
  if (m.triangle_face.empty()) m.triangle_face.assign(m.triangles.size(), 0);
  // A side beyond the surface cuts nothing: it is moved to just outside the surface, so that the
  // snapping tolerance follows the surface's size, not a box of 1e10 mm (which snapped every
  // vertex within millimetres onto its planes).
  Vec3 lo = box_lo, hi = box_hi;
  if (!m.vertices.empty()) {
    Vec3 mlo = m.vertices.front(), mhi = m.vertices.front();
    for (const auto& v : m.vertices) mlo = componentMin(mlo, v), mhi = componentMax(mhi, v);
    const double margin = 1e-3 * std::max({mhi.x - mlo.x, mhi.y - mlo.y, mhi.z - mlo.z, 1e-6}) + 1e-6;
    lo = componentMax(lo, mlo - Vec3(margin, margin, margin));
    hi = componentMin(hi, mhi + Vec3(margin, margin, margin));
    // A box that misses the surface altogether keeps nothing.
    if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) {
      keepTriangles(m, std::vector<char>(m.triangles.size(), 0));
      return rep;
    }
  }
  const double snap = 1e-9 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-300});
  for (int side = 0; side < 6; ++side) {
    const int axis = side / 2;
    const bool upper = side % 2 == 1;
    clipSide(m, axis, coord(upper ? hi : lo, axis), upper ? 1.0 : -1.0, snap, first_face + side, rep, side);
  }
  keepTriangles(m, std::vector<char>(m.triangles.size(), 1));  // drops the vertices left outside
  return rep;
}

}  // namespace angiosynth
