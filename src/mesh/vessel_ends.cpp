#include "mesh/vessel_ends.hpp"

#include "core/segment_grid.hpp"
#include "mesh/plane_clip.hpp"
#include "mesh/ring_mesh.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

namespace angiosynth {

namespace {

// The prolongation beyond each plane, in radii: the surface crosses the plane as a tube, a
// radius from the prolongation's round tip (longer ones merge with more neighbours).
constexpr double kOvershootRadii = 1;

// A vertex this close to a plane (share of the radius; or of its step, where that moves it by
// less than a quarter of its height over the far edge of each of its triangles, so none turns
// far or over) is moved onto it: cut points never fall next to a vertex, so no slivers and no
// loop edges of a hundredth of a step, which the cap (its vertices stay) would keep.
constexpr double kSnap = 1e-6, kSnapSteps = 0.05, kSnapHeight = 0.25;

std::uint64_t pairKey(std::int32_t a, std::int32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
}
std::uint64_t directedKey(std::int32_t a, std::int32_t b) { return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b); }

// The region an end's cut may touch: its tube from a radius (plus two steps) before the plane
// to the prolongation's tip, out to 1.5 radii (plus two steps) from the axis.
struct EndRegion {
  Vec3 c, n;
  double r;
  bool tight;
  double step;  // > 0: the end's step, else the vertex's
  bool holds(const Vec3& p, double vertex_step) const {
    const auto x = endCutExtent(r, step > 0 ? step : vertex_step, tight);
    const Vec3 v = p - c;
    const double s = dot(v, n), rho2 = dot(v, v) - s * s;
    return s >= -x.before && s <= x.beyond && rho2 <= x.reach * x.reach;
  }
  // Its bounding box.
  void box(Vec3& lo, Vec3& hi) const {
    const double h = 4 * r, reach = 1.5 * r + h;
    lo = hi = c - n * (r + h);
    for (const Vec3& p : {c - n * (r + h), c + n * ((kOvershootRadii + 1) * r + h)}) {
      lo = componentMin(lo, p - Vec3(reach, reach, reach));
      hi = componentMax(hi, p + Vec3(reach, reach, reach));
    }
  }
};

// (end, vertex) pairs of vertices inside each end's region, sorted: ends are binned on a grid of
// cells about as large as the typical region (larger regions are tested against every vertex).
std::vector<std::pair<std::int32_t, std::int32_t>> verticesNearEnds(const SurfaceMesh& m, const std::vector<EndRegion>& regions) {
  std::vector<double> sizes;
  for (const auto& e : regions) {
    Vec3 lo, hi;
    e.box(lo, hi);
    sizes.push_back(std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}));
  }
  std::vector<double> sorted = sizes;
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() * 9 / 10), sorted.end());
  const double g = std::max(sorted[sorted.size() * 9 / 10], 1e-9);
  const auto cellOf = [g](double v) { return std::int64_t(std::floor(v / g)); };
  const auto code = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (std::uint64_t(x & 0x1fffff) << 42) | (std::uint64_t(y & 0x1fffff) << 21) | std::uint64_t(z & 0x1fffff);
  };
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> bins;
  std::vector<std::int32_t> large;
  for (std::size_t e = 0; e < regions.size(); ++e) {
    if (sizes[e] > 4 * g) {
      large.push_back(std::int32_t(e));
      continue;
    }
    Vec3 lo, hi;
    regions[e].box(lo, hi);
    for (auto z = cellOf(lo.z); z <= cellOf(hi.z); ++z)
      for (auto y = cellOf(lo.y); y <= cellOf(hi.y); ++y)
        for (auto x = cellOf(lo.x); x <= cellOf(hi.x); ++x) bins[code(x, y, z)].push_back(std::int32_t(e));
  }
  tbb::enumerable_thread_specific<std::vector<std::pair<std::int32_t, std::int32_t>>> found;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m.vertices.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    auto& out = found.local();
    for (std::size_t v = r.begin(); v != r.end(); ++v) {
      const Vec3& p = m.vertices[v];
      const double step = m.vertex_step.empty() ? 0.0 : double(m.vertex_step[v]);
      const auto test = [&](std::int32_t e) {
        if (regions[std::size_t(e)].holds(p, step)) out.emplace_back(e, std::int32_t(v));
      };
      if (const auto it = bins.find(code(cellOf(p.x), cellOf(p.y), cellOf(p.z))); it != bins.end())
        for (auto e : it->second) test(e);
      for (auto e : large) test(e);
    }
  });
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  for (auto& f : found) pairs.insert(pairs.end(), f.begin(), f.end());
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace

EndCutExtent endCutExtent(double r, double step, bool tight) {
  if (tight) {
    const double h = std::min(step, 2 * r);
    return {1.5 * h, (kOvershootRadii + 1) * r + h, r + 0.5 * h};
  }
  const double h = 2 * std::min(step, 2 * r);
  return {r + h, (kOvershootRadii + 1) * r + h, 1.5 * r + h};
}

namespace {

// Shortens each end's extension where what it adds to the prolongation every cut end has (a
// radius past its plane) would come within its cut's reach of another vessel or of an extension
// decided before it: unchecked, the contour joined them into a handle. An extension that starts
// that near a vessel (a sibling it diverges from) but not joined to it (walls more than a contour
// step apart) may go on while it gets no nearer and its tip is not joined to it either. Whether
// the cut then finds its region clear is the cut's to report (ends left closed).
void keepExtensionsClear(const VascularTree& t, std::vector<VesselEnd>& ends, double extension_radii, double step_radii) {
  Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  double widest = 0;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    lo = componentMin(lo, t.position[i]), hi = componentMax(hi, t.position[i]);
    if (!t.isRoot(i)) widest = std::max({widest, t.radius[i], t.startRadius(i)});
  }
  // Within its cut's reach: what an extension keeps from the vessels it nears.
  const auto apart = [&](double r, double other) { return other + endCutExtent(r, step_radii * r).reach; };
  // Walls within the end's contour step: joined, the surface has a handle.
  const auto joined = [&](double r, double other) { return r + other + step_radii * r; };
  std::vector<double> lengths;
  double thickest_end = 0;
  for (const auto& e : ends) {
    lengths.push_back((extension_radii + kOvershootRadii) * e.radius);
    thickest_end = std::max(thickest_end, e.radius);
  }
  const double grow = *std::max_element(lengths.begin(), lengths.end()) + apart(thickest_end, widest);
  std::nth_element(lengths.begin(), lengths.begin() + std::ptrdiff_t(lengths.size() / 2), lengths.end());
  SegmentGrid grid(lo - Vec3(grow, grow, grow), hi + Vec3(grow, grow, grow), std::max(lengths[lengths.size() / 2], 1e-6), hi.z - lo.z <= 0);
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (!t.isRoot(i) && !t.isLink(i)) grid.insert(i, t.position[t.parent[i]], t.position[i], std::max(t.radius[i], t.startRadius(i)));

  struct Near {
    std::int32_t vessel;
    Vec3 a, b;
    double clearance;  // the least distance of the added part's axis from this one's
    double joined;     // nearer, the contour joins the two
    double at_start;   // the distance of its start from this one
  };
  std::vector<Near> near;
  // The extensions decided so far (ids nodeCount + k in the grid): two ends that face each other
  // must not both reach into the gap.
  struct Extension {
    Vec3 a, b;
    double radius;
  };
  std::vector<Extension> decided(ends.size());
  const std::int32_t first_extension = t.nodeCount();
  for (std::size_t k = 0; k < ends.size(); ++k) {
    auto& e = ends[k];
    const double r = e.radius;
    // The added part of an extension of `radii`: from the prolongation's tip on.
    const Vec3 start = e.node + e.normal * (kOvershootRadii * r);
    const auto tipOf = [&](double radii) { return e.node + e.normal * ((radii + kOvershootRadii) * r); };
    near.clear();
    grid.any(start, tipOf(extension_radii), apart(r, widest), [&](std::int32_t y) {
      if (y == e.vessel) return false;
      Near n;
      double other_radius;
      if (y >= first_extension) {
        const auto& other = decided[std::size_t(y - first_extension)];
        n = {ends[std::size_t(y - first_extension)].vessel, other.a, other.b, 0, 0, 0};
        other_radius = other.radius;
      } else {
        n = {y, t.position[t.parent[y]], t.position[y], 0, 0, 0};
        other_radius = std::max(t.radius[y], t.startRadius(y));
      }
      n.clearance = apart(r, other_radius);
      n.joined = joined(r, other_radius);
      n.at_start = pointSegmentDistance(start, n.a, n.b);
      near.push_back(n);
      return false;
    });
    // The vessel that stops an extension of `radii`, or -1: one it comes within its cut's reach
    // of, unless it started nearer (a sibling it diverges from), gets no nearer and its tip is
    // clear of being joined to it.
    const auto stop = [&](double radii) {
      const Vec3 tip = tipOf(radii);
      for (const auto& n : near) {
        const double d = segmentSegmentDistance(start, tip, n.a, n.b);
        if (d >= n.clearance) continue;
        if (n.at_start >= n.joined && d >= (1 - 1e-9) * n.at_start && pointSegmentDistance(tip, n.a, n.b) >= n.joined) continue;
        return n.vessel;
      }
      return std::int32_t(-1);
    };
    // The longest of 16 lengths down from the one asked that nothing stops (a diverging
    // extension may be stopped short and not long, so no bisection).
    constexpr int kLengths = 16;
    double given = extension_radii;
    if (const auto first = stop(given); first >= 0) {
      e.extension_stop = first;
      given = 0;
      for (int part = kLengths - 1; part > 0; --part)
        if (stop(extension_radii * part / kLengths) < 0) {
          given = extension_radii * part / kLengths;
          break;
        }
    }
    e.extension_radii = given;
    e.centre = e.node + e.normal * (given * r);
    decided[k] = {start, tipOf(given), r};
    grid.insert(first_extension + std::int32_t(k), decided[k].a, decided[k].b, r + apart(r, widest));
  }
}

}  // namespace

std::vector<VesselEnd> openEnds(const VascularTree& t, double extension_radii, double step_radii) {
  std::vector<VesselEnd> ends;
  const auto add = [&](std::int32_t vessel, bool root) {
    const std::int32_t node = root ? t.parent[vessel] : vessel, other = root ? vessel : t.parent[vessel];
    const Vec3 d = t.position[node] - t.position[other];
    if (!(norm(d) > 0)) return;
    VesselEnd e;
    e.vessel = vessel;
    e.tree = t.tree.empty() ? 0 : t.tree[vessel];
    e.root = root;
    e.node = t.position[node];
    e.normal = unit(d);
    e.radius = root ? t.startRadius(vessel) : t.radius[vessel];
    e.centre = e.node + e.normal * (extension_radii * e.radius);
    e.extension_radii = extension_radii;
    if (e.radius > 0) ends.push_back(e);
  };
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (t.isRoot(i) && t.child0[i] >= 0 && t.child1[i] < 0 && !t.isLink(t.child0[i])) add(t.child0[i], true);
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (!t.isRoot(i) && t.child0[i] < 0 && !t.isLink(i)) add(i, false);
  // In an order of the geometry alone, so a tree read back from its graph files (numbered
  // otherwise) gives the same files.
  std::sort(ends.begin(), ends.end(), [](const VesselEnd& a, const VesselEnd& b) {
    return std::make_tuple(a.tree, !a.root, a.node.x, a.node.y, a.node.z) < std::make_tuple(b.tree, !b.root, b.node.x, b.node.y, b.node.z);
  });
  if (extension_radii > 0 && !ends.empty()) keepExtensionsClear(t, ends, extension_radii, step_radii);
  return ends;
}

VascularTree prolongEnds(const VascularTree& t, const std::vector<VesselEnd>& ends) {
  VascularTree out = t;
  for (const auto& e : ends) {
    const std::int32_t node = e.root ? t.parent[e.vessel] : e.vessel;
    const auto id = out.addNode(e.centre + e.normal * (kOvershootRadii * e.radius), node);
    out.radius[id] = e.radius;
  }
  return out;
}

namespace {

// What the cut of every end shares: the mesh, the triangles of the vertices near an end, the
// triangles cut away so far, and for each vertex the end whose region it was last found in and
// its signed distance to that end's plane.
struct CutState {
  SurfaceMesh& m;
  const VertexTriangles& incident;
  std::vector<char> removed;
  std::vector<std::int32_t> region_of;
  std::vector<double> side;
};

// Snaps the end's vertices within kSnap·r (or a sliver's height) onto its plane and records their
// sides; the apex, the vertex nearest the prolongation's tip, or -1 when the end has none.
std::int32_t snapToPlane(CutState& st, const EndRegion& reg, std::int32_t e, const std::vector<std::int32_t>& local) {
  SurfaceMesh& m = st.m;
  std::int32_t apex = -1;
  double apex_distance = INFINITY;
  const Vec3 tip = reg.c + reg.n * ((kOvershootRadii + 1) * reg.r);
  for (auto v : local) {
    double s = dot(m.vertices[std::size_t(v)] - reg.c, reg.n);
    double snap = m.vertex_step.empty() ? 0.0 : kSnapSteps * double(m.vertex_step[std::size_t(v)]);
    if (std::abs(s) < snap)
      for (const auto k : st.incident.of(v)) {
        const auto& tri = m.triangles[std::size_t(k)];
        const int i = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
        const Vec3 p = m.vertices[std::size_t(v)], a = m.vertices[std::size_t(tri[std::size_t((i + 1) % 3)])],
                   b = m.vertices[std::size_t(tri[std::size_t((i + 2) % 3)])];
        snap = std::min(snap, kSnapHeight * norm(cross(a - p, b - p)) / std::max(norm(b - a), 1e-300));
      }
    if (std::abs(s) < std::max(snap, kSnap * reg.r)) {
      m.vertices[std::size_t(v)] = m.vertices[std::size_t(v)] - reg.n * s;
      s = 0;
    }
    st.region_of[std::size_t(v)] = e;
    st.side[std::size_t(v)] = s;
    const double d = distance(m.vertices[std::size_t(v)], tip);
    if (apex < 0 || d < apex_distance) apex = v, apex_distance = d;
  }
  return apex;
}

// The prolongation's triangles: those with a vertex beyond the plane connected to the apex, and
// the directed edges of the untouched neighbours facing them. False when one of their vertices
// lies outside the end's region (the prolongation merged with another vessel) or an edge has no
// triangle across.
bool collectProlongation(const CutState& st, std::int32_t e, std::int32_t apex, std::vector<std::int32_t>& cut,
                         std::vector<std::uint64_t>& boundary_side) {
  const SurfaceMesh& m = st.m;
  const auto mine = [&](std::int32_t v) { return st.region_of[std::size_t(v)] == e; };
  const auto beyond = [&](std::int32_t k) {
    const auto& tri = m.triangles[std::size_t(k)];
    return st.side[std::size_t(tri[0])] > 0 || st.side[std::size_t(tri[1])] > 0 || st.side[std::size_t(tri[2])] > 0;
  };
  std::unordered_set<std::int32_t> in_cut;
  for (const auto k : st.incident.of(apex))
    if (in_cut.insert(k).second) cut.push_back(k);
  // The triangle across edge (a, b) of triangle k, or −1.
  const auto across = [&](std::int32_t k, std::int32_t a, std::int32_t b) {
    for (const auto o : st.incident.of(a)) {
      if (o == k || st.removed[std::size_t(o)]) continue;
      const auto& tri = m.triangles[std::size_t(o)];
      if (tri[0] == b || tri[1] == b || tri[2] == b) return o;
    }
    return std::int32_t(-1);
  };
  for (std::size_t q = 0; q < cut.size(); ++q) {
    const auto k = cut[q];
    const auto& tri = m.triangles[std::size_t(k)];
    if (st.removed[std::size_t(k)] || !mine(tri[0]) || !mine(tri[1]) || !mine(tri[2])) return false;
    for (int i = 0; i < 3; ++i) {
      const auto a = tri[std::size_t(i)], b = tri[std::size_t((i + 1) % 3)];
      const auto o = across(k, a, b);
      if (o < 0) return false;
      if (in_cut.count(o)) continue;
      const auto& ot = m.triangles[std::size_t(o)];
      if ((mine(ot[0]) && mine(ot[1]) && mine(ot[2])) && beyond(o)) {
        in_cut.insert(o);
        cut.push_back(o);
      } else {
        boundary_side.push_back(directedKey(b, a));
      }
    }
  }
  return true;
}

// The prolongation clipped to the side s ≤ 0: the pieces kept and the new vertices on the plane
// (numbered from `base`, after the mesh's), cut points shared through their edge.
struct ClippedEnd {
  std::int32_t base = 0;
  std::vector<Vec3> new_vertices;
  std::vector<float> new_steps;
  std::vector<std::array<std::int32_t, 3>> kept;
  std::vector<std::int32_t> kept_tree;
};

ClippedEnd clipProlongation(const CutState& st, const EndRegion& reg, std::vector<std::int32_t>& cut) {
  const SurfaceMesh& m = st.m;
  ClippedEnd c;
  c.base = std::int32_t(m.vertices.size());
  std::unordered_map<std::uint64_t, std::int32_t> cut_point;
  const auto pointOn = [&](std::int32_t a, std::int32_t b) {
    const auto key = pairKey(a, b);
    if (const auto it = cut_point.find(key); it != cut_point.end()) return it->second;
    const double sa = st.side[std::size_t(a)], sb = st.side[std::size_t(b)];
    Vec3 p = m.vertices[std::size_t(a)] + (m.vertices[std::size_t(b)] - m.vertices[std::size_t(a)]) * (sa / (sa - sb));
    p = p - reg.n * dot(p - reg.c, reg.n);
    const auto id = c.base + std::int32_t(c.new_vertices.size());
    c.new_vertices.push_back(p);
    c.new_steps.push_back(m.vertex_step.empty() ? 0.f : std::min(m.vertex_step[std::size_t(a)], m.vertex_step[std::size_t(b)]));
    cut_point.emplace(key, id);
    return id;
  };
  const auto at_of = [&](std::int32_t v) -> const Vec3& {
    return v >= c.base ? c.new_vertices[std::size_t(v - c.base)] : m.vertices[std::size_t(v)];
  };
  std::sort(cut.begin(), cut.end());
  for (auto k : cut)
    clipTriangleToPlane(
        m.triangles[std::size_t(k)], [&](std::int32_t v) { return st.side[std::size_t(v)]; }, pointOn, at_of,
        [&](std::int32_t a, std::int32_t b, std::int32_t t) {
          c.kept.push_back({a, b, t});
          c.kept_tree.push_back(m.triangle_tree[std::size_t(k)]);
        });
  return c;
}

// The cut's loop: the directed edges of the kept pieces and of the neighbours facing the cut
// that have no reverse among them, all on the plane, from the lowest vertex; empty when they do
// not form one simple loop.
std::vector<std::int32_t> traceLoop(const CutState& st, const ClippedEnd& c, const std::vector<std::uint64_t>& boundary_side) {
  const auto sideOf = [&](std::int32_t v) { return v >= c.base ? 0.0 : st.side[std::size_t(v)]; };
  std::unordered_set<std::uint64_t> edges(boundary_side.begin(), boundary_side.end());
  for (const auto& tri : c.kept)
    for (int i = 0; i < 3; ++i) edges.insert(directedKey(tri[std::size_t(i)], tri[std::size_t((i + 1) % 3)]));
  std::unordered_map<std::int32_t, std::int32_t> next;
  std::int32_t start = -1;
  bool ok = true;
  for (auto key : edges) {
    const auto a = std::int32_t(key >> 32), b = std::int32_t(key & 0xffffffffu);
    if (edges.count(directedKey(b, a))) continue;
    if (sideOf(a) != 0 || sideOf(b) != 0 || !next.emplace(a, b).second) ok = false;
    if (start < 0 || a < start) start = a;
  }
  std::vector<std::int32_t> loop;
  for (std::int32_t v = start; ok && v >= 0;) {
    loop.push_back(v);
    const auto it = next.find(v);
    if (it == next.end())
      ok = false;
    else
      v = it->second == start ? -1 : it->second;
    if (loop.size() > next.size()) ok = false;
  }
  if (!ok || loop.size() < 3 || loop.size() != next.size()) return {};
  return loop;
}

// The cap of the loop: a fan from the plane's centre when the loop is star-shaped around it
// (seen along the outward normal; the centre becomes a new vertex), else the loop's ears. False
// when ear clipping finds no triangulation.
bool capLoop(const SurfaceMesh& m, ClippedEnd& c, const std::vector<std::int32_t>& loop, const VesselEnd& end, const EndRegion& reg,
             std::vector<std::array<std::int32_t, 3>>& cap, double& area) {
  const auto at_of = [&](std::int32_t v) -> const Vec3& {
    return v >= c.base ? c.new_vertices[std::size_t(v - c.base)] : m.vertices[std::size_t(v)];
  };
  const auto centre = c.base + std::int32_t(c.new_vertices.size());
  bool star = true;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const auto a = loop[i], b = loop[(i + 1) % loop.size()];
    const double twice = dot(cross(at_of(a) - end.centre, at_of(b) - end.centre), reg.n);
    star = star && twice < 0;  // the wall runs a → b; the cap runs b → a around the normal
  }
  if (star) {
    for (std::size_t i = 0; i < loop.size(); ++i) cap.push_back({loop[(i + 1) % loop.size()], loop[i], centre});
    float step = INFINITY;
    for (auto v : loop)
      step = std::min(step, v >= c.base ? c.new_steps[std::size_t(v - c.base)] : m.vertex_step.empty() ? 0.f : m.vertex_step[std::size_t(v)]);
    c.new_vertices.push_back(end.centre);
    c.new_steps.push_back(step);
  } else {
    std::vector<Vec3> polygon;
    for (std::size_t i = loop.size(); i-- > 0;) polygon.push_back(at_of(loop[i]));
    const Vec3 u = unit(std::abs(reg.n.x) < 0.9 ? cross(reg.n, Vec3(1, 0, 0)) : cross(reg.n, Vec3(0, 1, 0))), w = cross(reg.n, u);
    const auto ears = earClip(polygon, u, w);
    if (ears.empty()) return false;
    const auto vertexOf = [&](int i) { return loop[loop.size() - 1 - std::size_t(i)]; };
    for (const auto& ear : ears) cap.push_back({vertexOf(ear[0]), vertexOf(ear[1]), vertexOf(ear[2])});
  }
  for (const auto& tri : cap) area += 0.5 * norm(cross(at_of(tri[1]) - at_of(tri[0]), at_of(tri[2]) - at_of(tri[0])));
  return true;
}

}  // namespace

EndCutReport cutEnds(SurfaceMesh& m, const std::vector<VesselEnd>& ends, bool caps) {
  EndCutReport rep;
  rep.cap_area_mm2.assign(ends.size(), 0.0);
  rep.loop_vertices.assign(ends.size(), 0);
  m.triangle_face.assign(m.triangles.size(), 0);
  if (ends.empty() || m.triangles.empty()) return rep;
  std::vector<EndRegion> regions;
  for (const auto& e : ends) regions.push_back({e.centre, e.normal, e.radius, e.tight, e.tight ? e.step : 0.0});
  const auto near = verticesNearEnds(m, regions);

  // Triangles at each vertex near an end (vertex-to-triangle incidence of those vertices only).
  const std::size_t nv = m.vertices.size();
  std::vector<char> is_near(nv, 0);
  for (const auto& p : near) is_near[std::size_t(p.second)] = 1;
  const VertexTriangles incident(m, &is_near);
  CutState st{m, incident, std::vector<char>(m.triangles.size(), 0), std::vector<std::int32_t>(nv, -1), std::vector<double>(nv, 0.0)};
  std::size_t at = 0;
  for (std::size_t e = 0; e < ends.size(); ++e) {
    const auto& end = ends[e];
    const auto& reg = regions[e];
    std::vector<std::int32_t> local;
    for (; at < near.size() && near[at].first == std::int32_t(e); ++at) local.push_back(near[at].second);
    const auto leaveClosed = [&] { rep.left_closed.push_back(std::int32_t(e)); };
    const std::int32_t apex = snapToPlane(st, reg, std::int32_t(e), local);
    if (apex < 0 || !(st.side[std::size_t(apex)] > 0)) {
      leaveClosed();
      continue;
    }
    std::vector<std::int32_t> cut;
    std::vector<std::uint64_t> boundary_side;
    if (!collectProlongation(st, std::int32_t(e), apex, cut, boundary_side)) {
      leaveClosed();
      continue;
    }
    ClippedEnd clipped = clipProlongation(st, reg, cut);
    const std::vector<std::int32_t> loop = traceLoop(st, clipped, boundary_side);
    if (loop.empty()) {
      leaveClosed();
      continue;
    }
    std::vector<std::array<std::int32_t, 3>> cap;
    double area = 0;
    if (caps && !end.open && !capLoop(m, clipped, loop, end, reg, cap, area)) {
      leaveClosed();
      continue;
    }
    // Commit.
    for (auto k : cut) st.removed[std::size_t(k)] = 1;
    m.vertices.insert(m.vertices.end(), clipped.new_vertices.begin(), clipped.new_vertices.end());
    if (!m.vertex_step.empty()) m.vertex_step.insert(m.vertex_step.end(), clipped.new_steps.begin(), clipped.new_steps.end());
    for (std::size_t i = 0; i < clipped.kept.size(); ++i) {
      m.triangles.push_back(clipped.kept[i]);
      m.triangle_tree.push_back(clipped.kept_tree[i]);
      m.triangle_face.push_back(0);
      st.removed.push_back(0);
    }
    for (const auto& tri : cap) {
      m.triangles.push_back(tri);
      m.triangle_tree.push_back(end.tree);
      m.triangle_face.push_back(std::int32_t(e) + 1);
      st.removed.push_back(0);
    }
    ++rep.cut;
    rep.cap_area_mm2[e] = area;
    rep.loop_vertices[e] = std::int32_t(loop.size());
  }

  // Drop the prolongations and the vertices only they used; the others keep their order.
  for (auto& r : st.removed) r = !r;
  keepTriangles(m, st.removed);
  return rep;
}

}  // namespace angiosynth
