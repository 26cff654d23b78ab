#include "mesh/decimate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <queue>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace angiosynth {

namespace {

// Σ w·(n·p + d)² over planes, as the symmetric 4×4 matrix of (x, y, z, 1).
struct Quadric {
  double xx = 0, xy = 0, xz = 0, xw = 0, yy = 0, yz = 0, yw = 0, zz = 0, zw = 0, ww = 0;
  void addPlane(const Vec3& n, double d, double w) {
    xx += w * n.x * n.x, xy += w * n.x * n.y, xz += w * n.x * n.z, xw += w * n.x * d;
    yy += w * n.y * n.y, yz += w * n.y * n.z, yw += w * n.y * d;
    zz += w * n.z * n.z, zw += w * n.z * d, ww += w * d * d;
  }
  // Triangle abc's plane, weighted by its area (nothing for a degenerate one).
  void addTriangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = cross(b - a, c - a);
    const double area2 = norm(n);
    if (!(area2 > 0)) return;
    const Vec3 u = n / area2;
    addPlane(u, -dot(u, a), 0.5 * area2);
  }
  Quadric& operator+=(const Quadric& q) {
    xx += q.xx, xy += q.xy, xz += q.xz, xw += q.xw, yy += q.yy, yz += q.yz, yw += q.yw, zz += q.zz, zw += q.zw, ww += q.ww;
    return *this;
  }
  double operator()(const Vec3& v) const {
    return xx * v.x * v.x + 2 * xy * v.x * v.y + 2 * xz * v.x * v.z + 2 * xw * v.x + yy * v.y * v.y + 2 * yz * v.y * v.z + 2 * yw * v.y +
           zz * v.z * v.z + 2 * zw * v.z + ww;
  }
  // A x = r for the quadric's 3×3 part plus alpha·I (Cramer's rule).
  bool solve(double alpha, const Vec3& r, Vec3& x) const {
    const double a = xx + alpha, e = yy + alpha, i = zz + alpha;
    const double det = a * (e * i - yz * yz) - xy * (xy * i - yz * xz) + xz * (xy * yz - e * xz);
    if (!(std::abs(det) > 0)) return false;
    x.x = (r.x * (e * i - yz * yz) - xy * (r.y * i - yz * r.z) + xz * (r.y * yz - e * r.z)) / det;
    x.y = (a * (r.y * i - yz * r.z) - r.x * (xy * i - yz * xz) + xz * (xy * r.z - r.y * xz)) / det;
    x.z = (a * (e * r.z - r.y * yz) - xy * (xy * r.z - r.y * xz) + r.x * (xy * yz - e * xz)) / det;
    return std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z);
  }
};

// The cosines of a triangle's angles at a, b and c: angles compare as their cosines do,
// reversed, without an arc function.
std::array<double, 3> cornerCosines(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, bc = c - b, ca = a - c;
  const double lab = dot(ab, ab), lbc = dot(bc, bc), lca = dot(ca, ca);
  return {-dot(ab, ca) / std::sqrt(lab * lca), -dot(bc, ab) / std::sqrt(lbc * lab), -dot(ca, bc) / std::sqrt(lca * lbc)};
}

// The cosine of a triangle's smallest angle (the largest of its corners' cosines).
double smallestAngleCosine(const std::array<double, 3>& at) {
  const double m = std::max({at[0], at[1], at[2]});
  return std::isfinite(m) ? m : 1.0;
}
double smallestAngleCosine(const Vec3& a, const Vec3& b, const Vec3& c) { return smallestAngleCosine(cornerCosines(a, b, c)); }

// The cosine of a triangle's largest angle (the smallest of its corners' cosines), and the corner.
double largestAngleCosine(const std::array<double, 3>& at, int* corner = nullptr) {
  const int i = at[0] <= at[1] && at[0] <= at[2] ? 0 : at[1] <= at[2] ? 1 : 2;
  if (corner) *corner = i;
  return std::isfinite(at[i]) ? at[i] : -1.0;
}
double largestAngleCosine(const Vec3& a, const Vec3& b, const Vec3& c, int* corner = nullptr) {
  return largestAngleCosine(cornerCosines(a, b, c), corner);
}

// A triangle's shape: 4√3 × area / the sum of its squared edges, 1 when equilateral, 0 when flat.
double quality(const Vec3* p) {
  const double l2 = dot(p[1] - p[0], p[1] - p[0]) + dot(p[2] - p[1], p[2] - p[1]) + dot(p[0] - p[2], p[0] - p[2]);
  const double q = 2 * std::sqrt(3.0) * norm(cross(p[1] - p[0], p[2] - p[0])) / l2;
  return std::isfinite(q) ? q : 0.0;
}

// A sliver: an angle below the bound, or an edge shorter than kShortEdge of its ends' step (a
// tetrahedral mesher grades its elements down to the shortest edge near it).
constexpr double kShortEdge = 0.35;
bool isSliver(const SurfaceMesh& m, const std::array<std::int32_t, 3>& t, double cos_sliver) {
  const Vec3 p0 = m.vertices[std::size_t(t[0])], p1 = m.vertices[std::size_t(t[1])], p2 = m.vertices[std::size_t(t[2])];
  if (smallestAngleCosine(p0, p1, p2) > cos_sliver) return true;
  if (m.vertex_step.empty()) return false;
  const double step = std::min({m.vertex_step[std::size_t(t[0])], m.vertex_step[std::size_t(t[1])], m.vertex_step[std::size_t(t[2])]});
  const double shortest2 = std::min({dot(p1 - p0, p1 - p0), dot(p2 - p1, p2 - p1), dot(p0 - p2, p0 - p2)});
  return shortest2 < kShortEdge * kShortEdge * step * step;
}

// What a pass does; the repair passes (sliver, obtuse) take on only the triangles needsRepair names.
enum class Pass { collapse, flip, sliver, obtuse };

// A triangle the repair pass `kind` takes on: a sliver (cos_bound: the cosine of sliver_deg), or
// one with an angle above obtuse_deg (cos_bound: its cosine).
bool needsRepair(const SurfaceMesh& m, const std::array<std::int32_t, 3>& t, Pass kind, double cos_bound) {
  if (kind == Pass::sliver) return isSliver(m, t, cos_bound);
  return largestAngleCosine(m.vertices[std::size_t(t[0])], m.vertices[std::size_t(t[1])], m.vertices[std::size_t(t[2])]) < cos_bound;
}

// Component-wise min and max of finite points, inlined: std::fmin and fmax are calls into libm,
// and the repair makes many.
Vec3 lower(const Vec3& a, const Vec3& b) { return {a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z}; }
Vec3 upper(const Vec3& a, const Vec3& b) { return {a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z}; }
// A triangle's bounding box, and whether two boxes are apart on some axis.
void triangleBox(const Vec3& a, const Vec3& b, const Vec3& c, Vec3& lo, Vec3& hi) { lo = lower(lower(a, b), c), hi = upper(upper(a, b), c); }
bool boxesApart(const Vec3& lo1, const Vec3& hi1, const Vec3& lo2, const Vec3& hi2) {
  for (int ax = 0; ax < 3; ++ax)
    if (hi1[ax] < lo2[ax] || lo1[ax] > hi2[ax]) return true;
  return false;
}

double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) { return dot(b - a, cross(c - a, d - a)); }

// Segment p–q passes through the inside of triangle abc (touching counts as not: vertices
// shared between the two are handled by the caller).
bool crosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double sp = orient(a, b, c, p), sq = orient(a, b, c, q);
  if (!((sp > 0 && sq < 0) || (sp < 0 && sq > 0))) return false;
  const double s1 = orient(p, q, a, b), s2 = orient(p, q, b, c), s3 = orient(p, q, c, a);
  return (s1 > 0 && s2 > 0 && s3 > 0) || (s1 < 0 && s2 < 0 && s3 < 0);
}

// Triangles (by vertex ids and positions) that cut through each other. Sharing an edge, they
// can only fold onto each other (the caller's normal check); sharing a vertex, only their
// opposite edges can cross the other.
bool intersect(const std::array<std::int32_t, 3>& s, const Vec3* ps, const std::array<std::int32_t, 3>& t, const Vec3* pt) {
  int shared = 0;
  for (auto a : s)
    for (auto b : t) shared += a == b;
  if (shared >= 2) return false;
  // Most pairs: t's vertices other than a shared one wholly on one side of s's plane (they can
  // meet at the shared vertex only).
  int above = 0, below = 0;
  for (int i = 0; i < 3; ++i) {
    if (std::find(s.begin(), s.end(), t[std::size_t(i)]) != s.end()) continue;
    const double o = orient(ps[0], ps[1], ps[2], pt[i]);
    above += o > 0, below += o < 0;
  }
  if (above == 3 - shared || below == 3 - shared) return false;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& e = pass == 0 ? s : t;
    const Vec3* pe = pass == 0 ? ps : pt;
    const auto& f = pass == 0 ? t : s;
    const Vec3* pf = pass == 0 ? pt : ps;
    for (int i = 0; i < 3; ++i) {
      const auto a = e[std::size_t(i)], b = e[std::size_t((i + 1) % 3)];
      if (shared == 1 && (std::find(f.begin(), f.end(), a) != f.end() || std::find(f.begin(), f.end(), b) != f.end())) continue;
      if (crosses(pe[i], pe[(i + 1) % 3], pf[0], pf[1], pf[2])) return true;
    }
  }
  return false;
}

struct Candidate {
  double cost;
  std::int32_t u, v;
  std::uint32_t version_u, version_v;
  bool operator<(const Candidate& o) const {  // for a min-heap on (cost, u, v)
    if (cost != o.cost) return cost > o.cost;
    if (u != o.u) return u > o.u;
    return v > o.v;
  }
};

// What every worker shares: the mesh, each vertex's triangles, quadric, version, state and
// block; a worker changes only what lies in its block.
struct State {
  State(SurfaceMesh& mesh, const DecimateOptions& options, const std::function<double(std::int32_t, const Vec3&)>& dist)
      : m(mesh),
        o(options),
        distance(dist),
        around(mesh.vertices.size()),
        quadric(mesh.vertices.size()),
        version(mesh.vertices.size(), 0),
        vertex_alive(mesh.vertices.size(), 1),
        locked(mesh.vertices.size(), 0),
        triangle_alive(mesh.triangles.size(), 1),
        boundary(mesh.vertices.size(), 0),
        block(mesh.vertices.size(), 0),
        visited(mesh.triangles.size(), 0) {
    for (std::size_t k = 0; k < m.triangles.size(); ++k) {
      const auto& t = m.triangles[k];
      for (auto v : t) around[std::size_t(v)].push_back(std::int32_t(k));
      if (!m.triangle_face.empty() && m.triangle_face[k] != 0)
        for (auto v : t) locked[std::size_t(v)] = 1;
      Quadric q;
      q.addTriangle(m.vertices[std::size_t(t[0])], m.vertices[std::size_t(t[1])], m.vertices[std::size_t(t[2])]);
      for (auto v : t) quadric[std::size_t(v)] += q;
    }
    // A vertex on a boundary loop has one more neighbour than triangles.
    std::vector<std::int32_t> ring;
    for (std::size_t v = 0; v < around.size(); ++v) {
      ring.clear();
      for (auto k : around[v])
        for (auto x : m.triangles[std::size_t(k)])
          if (x != std::int32_t(v)) ring.push_back(x);
      std::sort(ring.begin(), ring.end());
      if (std::size_t(std::unique(ring.begin(), ring.end()) - ring.begin()) != around[v].size()) locked[v] = boundary[v] = 1;
    }
  }

  void compact(std::vector<std::int32_t>* renumber) { keepTriangles(m, triangle_alive, renumber); }

  // A new free vertex (remeshing's split), with every per-vertex record; its id.
  std::int32_t addVertex(const Vec3& p, float step, std::int64_t in_block, std::vector<std::int32_t> triangles, const Quadric& q) {
    m.vertices.push_back(p);
    if (!m.vertex_step.empty()) m.vertex_step.push_back(step);
    around.push_back(std::move(triangles));
    quadric.push_back(q);
    version.push_back(0);
    vertex_alive.push_back(1);
    locked.push_back(0);
    boundary.push_back(0);
    block.push_back(in_block);
    if (!changed.empty()) changed.push_back(0);
    return std::int32_t(m.vertices.size() - 1);
  }
  // A new wall triangle, with every per-triangle record; its id (the caller links its vertices).
  std::int32_t addTriangle(const std::array<std::int32_t, 3>& t, std::int32_t tree) {
    m.triangles.push_back(t);
    m.triangle_tree.push_back(tree);
    if (!m.triangle_face.empty()) m.triangle_face.push_back(0);
    triangle_alive.push_back(1);
    visited.push_back(0);
    if (!failed.empty()) failed.push_back(0);
    return std::int32_t(m.triangles.size() - 1);
  }

  SurfaceMesh& m;
  const DecimateOptions& o;
  const std::function<double(std::int32_t, const Vec3&)>& distance;
  std::vector<std::vector<std::int32_t>> around;  // per vertex, its triangles
  std::vector<Quadric> quadric;
  std::vector<std::uint32_t> version;
  std::vector<char> vertex_alive, locked, triangle_alive, boundary;
  std::vector<std::int64_t> block;  // per vertex, the block of the current pass
  // Sliver repair: when a vertex's neighbourhood last changed, and when a triangle's repair last
  // failed (as (pass << 40) + the block's count of changes), so that a failed repair is tried
  // again only once something near it has changed.
  std::vector<std::uint64_t> changed, failed;
  std::vector<std::uint64_t> visited;  // per triangle, the last search of the triangles near a change that met it
  std::uint64_t pass = 0;
  bool at_fixed_only = false;  // sliver repair: only triangles with a fixed vertex
};

// One block's collapses or flips: only where everything read and written lies in the block, so
// blocks run in parallel and the result does not depend on the thread count.
class Worker {
 public:
  Worker(State& s, std::int64_t block)
      : st_(s),
        m_(s.m),
        o_(s.o),
        distance_(s.distance),
        around_(s.around),
        quadric_(s.quadric),
        version_(s.version),
        vertex_alive_(s.vertex_alive),
        locked_(s.locked),
        triangle_alive_(s.triangle_alive),
        block_(s.block),
        mine_(block) {
    cos_turn_ = std::cos(o_.max_turn_deg * std::numbers::pi / 180);
    cos_min_angle_ = std::cos(o_.min_angle_deg * std::numbers::pi / 180);
    cos_sliver_ = std::cos(o_.sliver_deg * std::numbers::pi / 180);
    cos_obtuse_ = std::cos(o_.obtuse_deg * std::numbers::pi / 180);
  }

  std::int64_t collapses = 0, flips = 0, moves = 0, removed = 0;
  double largest_error = 0;

  // Collapses among the edges of `triangles` (and those their collapses make) until none is allowed.
  void collapsePass(const std::int32_t* first, const std::int32_t* last) {
    for (auto k = first; k != last; ++k) {
      if (!triangle_alive_[std::size_t(*k)]) continue;
      const auto& t = m_.triangles[std::size_t(*k)];
      for (int i = 0; i < 3; ++i)
        if (t[std::size_t(i)] < t[std::size_t((i + 1) % 3)]) push(t[std::size_t(i)], t[std::size_t((i + 1) % 3)]);
    }
    std::vector<std::int32_t> ring;
    while (!queue_.empty()) {
      const Candidate c = queue_.top();
      queue_.pop();
      if (!vertex_alive_[std::size_t(c.u)] || !vertex_alive_[std::size_t(c.v)] || version_[std::size_t(c.u)] != c.version_u ||
          version_[std::size_t(c.v)] != c.version_v)
        continue;
      Vec3 w;
      double error = 0;
      auto [u, v] = survivorFirst(c.u, c.v);
      if (!allowed(u, v, w, error)) continue;
      collapse(u, v, w);
      largest_error = std::max(largest_error, error);
      ++collapses;
      neighbours(u, ring);
      for (auto x : ring) push(std::min(u, x), std::max(u, x));
    }
  }

  // Slivers or obtuse triangles (`kind`) among `triangles`, from a work list: each repair queues
  // the triangles it changed, and a failed one is tried again only once something near it has
  // changed.
  void repairPass(const std::int32_t* first, const std::int32_t* last, Pass kind) {
    const bool obtuse = kind == Pass::obtuse;
    const double cos_bound = obtuse ? cos_obtuse_ : cos_sliver_;
    joins_caps_ = !obtuse;
    work_.assign(first, last);
    // A bound on the work, against cycles of moves.
    const std::size_t budget = kSliverWork * work_.size() + 64;
    for (std::size_t next = 0; next < work_.size() && next < budget; ++next) {
      const auto k = work_[next];
      if (!triangle_alive_[std::size_t(k)]) continue;
      const auto& t = m_.triangles[std::size_t(k)];
      const auto failed = st_.failed[std::size_t(k)];
      if (failed > 0 && std::none_of(t.begin(), t.end(), [&](std::int32_t v) { return st_.changed[std::size_t(v)] > failed; })) continue;
      if (!needsRepair(m_, t, kind, cos_bound)) continue;
      blocked_ = false;
      if (!(obtuse ? repairObtuse(k) : repair(k)) && !blocked_) st_.failed[std::size_t(k)] = stamp();
    }
  }

  // One round of isotropic remeshing (Botsch and Kobbelt) toward edges of `target` × their ends'
  // step: edges longer than 4/3 of it split (longest first), edges shorter than 4/5 collapse
  // (shortest first, no edge left longer than 4/3; a boundary loop's too, into the survivor),
  // flips that raise the smallest angle, then flips towards valence 6, and every free vertex
  // moved towards its neighbours' mean where that betters its star's worst triangle. Each change
  // under the checks of decimation. Serial: the caller's one block.
  void remeshRound(double target) {
    for (const bool split_pass : {true, false}) {
      edges_.clear();
      for (std::size_t k = 0; k < m_.triangles.size(); ++k) {
        if (!triangle_alive_[k] || faceOf(std::int32_t(k)) != 0) continue;
        const auto& t = m_.triangles[k];
        for (int i = 0; i < 3; ++i) {
          const auto a = t[std::size_t(i)], b = t[std::size_t((i + 1) % 3)];
          if (a > b && (split_pass || triangleWith(b, a) >= 0)) continue;  // each inner edge once; a loop's edge, collapsing
          const double len = distance(m_.vertices[std::size_t(a)], m_.vertices[std::size_t(b)]), aim = target * std::min(stepOf(a), stepOf(b));
          if (split_pass ? len > kLongEdge * aim : len < kShortRemesh * aim) edges_.push_back({split_pass ? -len : len, a, b});
        }
      }
      std::sort(edges_.begin(), edges_.end());
      for (const auto& e : edges_) {
        if (!vertex_alive_[std::size_t(e.a)] || !vertex_alive_[std::size_t(e.b)]) continue;
        if (split_pass) {
          splits += split(e.a, e.b);
          continue;
        }
        const double len = distance(m_.vertices[std::size_t(e.a)], m_.vertices[std::size_t(e.b)]);
        if (!(len < kShortRemesh * target * std::min(stepOf(e.a), stepOf(e.b))) || triangleWith(e.a, e.b) < 0) continue;
        auto [u, v] = survivorFirst(e.a, e.b);
        Vec3 w;
        double error = 0;
        if (!allowed(u, v, w, error, target * kLongEdge)) continue;
        collapse(u, v, w);
        largest_error = std::max(largest_error, error);
        ++collapses;
      }
    }
    // Flips that raise the smallest angle, then those that bring the valences nearer 6 (the nets'
    // and their splits' lattices of squares are fixed points of the angles' flips and of the
    // moves: only a change of valence breaks them).
    for (const bool valence : {false, true})
      for (std::size_t k = 0; k < m_.triangles.size(); ++k)
        for (int i = 0; i < 3 && triangle_alive_[k]; ++i) {
          const auto a = m_.triangles[k][std::size_t(i)], b = m_.triangles[k][std::size_t((i + 1) % 3)];
          if (a > b || (valence && !betterValences(std::int32_t(k), a, b))) continue;
          flips += flip(std::int32_t(k), a, b, false, valence);
        }
    for (std::size_t x = 0; x < m_.vertices.size(); ++x)
      if (vertex_alive_[x] && !around_[x].empty() && relax(std::int32_t(x), m_.triangle_tree[std::size_t(around_[x][0])], Aim::quality)) ++moves;
  }
  std::int64_t splits = 0;

  // Flipping a–b of triangle k to c–d lowers the four vertices' total distance from their regular valence.
  bool betterValences(std::int32_t k, std::int32_t a, std::int32_t b) const {
    const std::int32_t k2 = across(k, a, b);
    if (k2 < 0) return false;
    const std::int32_t c = thirdOf(k, a, b), d = thirdOf(k2, a, b);
    const int before = valenceExcess(a, 0) + valenceExcess(b, 0) + valenceExcess(c, 0) + valenceExcess(d, 0);
    return valenceExcess(a, -1) + valenceExcess(b, -1) + valenceExcess(c, 1) + valenceExcess(d, 1) < before;
  }

  // One sweep over the edges of `triangles`, in order.
  void flipPass(const std::int32_t* first, const std::int32_t* last) {
    for (auto k = first; k != last; ++k)
      for (int i = 0; i < 3 && triangle_alive_[std::size_t(*k)]; ++i) {
        const auto a = m_.triangles[std::size_t(*k)][std::size_t(i)], b = m_.triangles[std::size_t(*k)][std::size_t((i + 1) % 3)];
        if (a < b && flip(*k, a, b)) ++flips;
      }
  }

 private:
  static constexpr double kFlatFlip = 0.9848;  // cos 10°
  // What a corner's move must improve: the smallest angle, the largest, or (remeshing) the star's
  // worst shape (quality(), the smallest angle staying above the floor or where it was).
  enum class Aim { smallest, largest, quality };

  // The ends of an edge to collapse, the one that stays first: a locked vertex (it keeps its
  // place, and its id: boundary loops are known by their vertex ids), else the lower id.
  std::pair<std::int32_t, std::int32_t> survivorFirst(std::int32_t a, std::int32_t b) const {
    if (a > b) std::swap(a, b);
    if (locked_[std::size_t(b)] && !locked_[std::size_t(a)]) std::swap(a, b);
    return {a, b};
  }

  static constexpr std::size_t kSliverWork = 8;
  // A sliver's edge between two vertices of one cap, shorter than this share of their step, joins
  // them (the survivor stays where it is, in the cap's plane): the cut made it, and a tetrahedral
  // mesher would refine around it.
  static constexpr double kCapJoin = 0.1;

  bool joins_caps_ = false;  // in the sliver passes only
  bool joinsCapVertices(std::int32_t u, std::int32_t v) const {
    if (!joins_caps_ || st_.boundary[std::size_t(u)] || st_.boundary[std::size_t(v)] || m_.triangle_face.empty()) return false;
    if (!(distance(m_.vertices[std::size_t(u)], m_.vertices[std::size_t(v)]) < kCapJoin * std::min(stepOf(u), stepOf(v)))) return false;
    for (auto k : around_[std::size_t(u)]) {
      const auto& t = m_.triangles[std::size_t(k)];
      if (m_.triangle_face[std::size_t(k)] != 0 && (t[0] == v || t[1] == v || t[2] == v)) return true;
    }
    return false;
  }

  // The worker's clock: unique within the pass, rising, and above every earlier pass's.
  std::uint64_t stamp() { return (st_.pass << 40) + ++changes_; }
  // x and its neighbours have changed; x's triangles are queued for the sliver pass.
  void touch(std::int32_t x) {
    const auto now = stamp();
    st_.changed[std::size_t(x)] = now;
    neighbours(x, touched_);
    for (auto y : touched_) st_.changed[std::size_t(y)] = now;
    for (auto k : around_[std::size_t(x)]) {
      const auto& t = m_.triangles[std::size_t(k)];
      if (block_[std::size_t(t[0])] == mine_ && block_[std::size_t(t[1])] == mine_ && block_[std::size_t(t[2])] == mine_) work_.push_back(k);
    }
  }

  // A sliver goes the first way the checks allow: one of its edges collapses, shortest first (a
  // needle's short edge; a cap's apex onto the nearer end of its long edge); a cap's long edge
  // flips; one of its corners moves (relax).
  bool repair(std::int32_t k) {
    const auto t = m_.triangles[std::size_t(k)];
    const Vec3 p[3] = {m_.vertices[std::size_t(t[0])], m_.vertices[std::size_t(t[1])], m_.vertices[std::size_t(t[2])]};
    // Edge i runs from t[i] to t[i + 1].
    double len[3];
    for (int i = 0; i < 3; ++i) len[i] = distance(p[i], p[(i + 1) % 3]);
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int x, int y) { return len[x] < len[y] || (len[x] == len[y] && x < y); });
    for (int e : order) {
      const auto [u, v] = survivorFirst(t[std::size_t(e)], t[std::size_t((e + 1) % 3)]);
      Vec3 w;
      double error = 0;
      if (!allowed(u, v, w, error)) continue;
      collapse(u, v, w);
      largest_error = std::max(largest_error, error);
      ++collapses;
      touch(u);
      return true;
    }
    const int longest = order[2];
    const double l1 = len[(longest + 1) % 3], l2 = len[(longest + 2) % 3];
    if (len[longest] * len[longest] > l1 * l1 + l2 * l2 && flipped(k, longest, true)) return true;
    for (int i = 0; i < 3; ++i)
      if (relaxed(k, i, Aim::smallest)) return true;
    return false;
  }
  // Edge i of triangle k (from t[i] to t[i + 1]) flipped; its four vertices' triangles queued.
  bool flipped(std::int32_t k, int i, bool cap) {
    const auto t = m_.triangles[std::size_t(k)];
    if (!flip(k, t[std::size_t(i)], t[std::size_t((i + 1) % 3)], cap)) return false;
    ++flips;
    for (auto x : {t[0], t[1], t[2]}) touch(x);
    for (auto x : m_.triangles[std::size_t(k)]) touch(x);  // the far vertex among them
    return true;
  }
  // Corner i of triangle k moved (relax); its triangles queued.
  bool relaxed(std::int32_t k, int i, Aim aim) {
    const auto x = m_.triangles[std::size_t(k)][std::size_t(i)];
    if (!relax(x, m_.triangle_tree[std::size_t(k)], aim)) return false;
    ++moves;
    touch(x);
    return true;
  }

  // An obtuse triangle's long edge encroaches on its opposite corner: a tetrahedral mesher
  // splits it, and the split's neighbours in turn. Its long edge flips (a Delaunay flip), else
  // one of its corners moves (relax) where that lowers the largest angle around it.
  bool repairObtuse(std::int32_t k) {
    const auto t = m_.triangles[std::size_t(k)];
    int c = 0;
    largestAngleCosine(m_.vertices[std::size_t(t[0])], m_.vertices[std::size_t(t[1])], m_.vertices[std::size_t(t[2])], &c);
    if (flipped(k, (c + 1) % 3, false)) return true;
    for (int i = 0; i < 3; ++i)
      if (relaxed(k, (c + i) % 3, Aim::largest)) return true;
    return false;
  }

  // Moves x to the mean of its neighbours, then along its star's normal to where the star keeps
  // its volume (the volume is linear in x's position), if that raises the smallest angle of its
  // triangles (Aim::largest: lowers the largest, the smallest staying above the floor or where it
  // was) and passes the checks of a collapse (turn, distance, nothing nearby cut). It keeps its
  // offset from the surface rather than being put onto it, which loses volume at every corner.
  bool relax(std::int32_t x, std::int32_t tree, Aim aim = Aim::smallest) {
    if (locked_[std::size_t(x)]) return false;
    neighbours(x, ring_u_);
    if (ring_u_.empty() || !mine(ring_u_)) return false;
    Vec3 c(0, 0, 0);
    for (auto y : ring_u_) c += m_.vertices[std::size_t(y)];
    c = c / double(ring_u_.size());
    // 6 × the star's volume as cones from the origin is x · g.
    Vec3 g(0, 0, 0);
    for (auto k : around_[std::size_t(x)]) {
      const auto& t = m_.triangles[std::size_t(k)];
      const int i = t[0] == x ? 0 : t[1] == x ? 1 : 2;
      g += cross(m_.vertices[std::size_t(t[std::size_t((i + 1) % 3)])], m_.vertices[std::size_t(t[std::size_t((i + 2) % 3)])]);
    }
    if (!(dot(g, g) > 0)) return false;
    c = c + g * (dot(m_.vertices[std::size_t(x)] - c, g) / dot(g, g));
    double old_cos = -1, new_cos = -1, old_big = 1, new_big = 1, old_q = 1, new_q = 1;
    const Vec3 star = starNormal(x, x);
    moved_.clear();
    for (auto k : around_[std::size_t(x)]) {
      const auto& t = m_.triangles[std::size_t(k)];
      Vec3 before[3], after[3];
      for (int i = 0; i < 3; ++i) {
        before[i] = m_.vertices[std::size_t(t[std::size_t(i)])];
        after[i] = t[std::size_t(i)] == x ? c : before[i];
      }
      const auto cos_before = cornerCosines(before[0], before[1], before[2]), cos_after = cornerCosines(after[0], after[1], after[2]);
      old_cos = std::max(old_cos, smallestAngleCosine(cos_before));
      new_cos = std::max(new_cos, smallestAngleCosine(cos_after));
      old_big = std::min(old_big, largestAngleCosine(cos_before));
      new_big = std::min(new_big, largestAngleCosine(cos_after));
      if (aim == Aim::quality) old_q = std::min(old_q, quality(before)), new_q = std::min(new_q, quality(after));
      if (turnsOver(before, after, star)) return false;
      moved_.push_back({t, {after[0], after[1], after[2]}});
    }
    const bool better = aim == Aim::smallest  ? new_cos < old_cos - 1e-3
                        : aim == Aim::largest ? new_big > old_big + 1e-3 && new_cos <= std::max(cos_min_angle_, old_cos)
                                              : new_q > old_q + 1e-4 && new_cos <= std::max(cos_min_angle_, old_cos);
    if (!better) return false;
    // The distances last: they cost the most.
    const double limit = o_.max_error * stepOf(x);
    if (!(std::abs(distance_(tree, c)) <= limit)) return false;
    for (const auto& mv : moved_)
      if (!(std::abs(distance_(tree, (mv.at[0] + mv.at[1] + mv.at[2]) / 3.0)) <= limit)) return false;
    if (cutsNear(ring_u_, [&](const std::array<std::int32_t, 3>& t, std::int32_t) { return t[0] == x || t[1] == x || t[2] == x; })) return false;
    m_.vertices[std::size_t(x)] = c;
    ++version_[std::size_t(x)];
    return true;
  }

  // The area-weighted normal of the triangles around a and b.
  Vec3 starNormal(std::int32_t a, std::int32_t b) const {
    Vec3 n(0, 0, 0);
    for (const std::int32_t end : {a, b})
      for (auto k : around_[std::size_t(end)]) {
        const auto& t = m_.triangles[std::size_t(k)];
        if (end == b && a != b && (t[0] == a || t[1] == a || t[2] == a)) continue;  // counted from a
        n += cross(m_.vertices[std::size_t(t[1])] - m_.vertices[std::size_t(t[0])], m_.vertices[std::size_t(t[2])] - m_.vertices[std::size_t(t[0])]);
      }
    return n;
  }
  // A moved triangle degenerates or turns by more than the bound from its normal before; a
  // sliver's normal is noise, so it is held to its star's instead.
  bool turnsOver(const Vec3* before, const Vec3* after, const Vec3& star) const {
    const Vec3 n1 = cross(after[1] - after[0], after[2] - after[0]);
    const Vec3 n0 = smallestAngleCosine(before[0], before[1], before[2]) > cos_sliver_ ? star : cross(before[1] - before[0], before[2] - before[0]);
    return !(norm(n1) > 0) || !(dot(n0, n1) >= cos_turn_ * norm(n0) * norm(n1));
  }

  bool mine(std::int32_t v) const {
    const bool in = block_[std::size_t(v)] == mine_;
    blocked_ |= !in;
    return in;
  }
  bool ringMine(std::int32_t v) const {
    for (auto k : around_[std::size_t(v)])
      for (auto x : m_.triangles[std::size_t(k)])
        if (!mine(x)) return false;
    return true;
  }
  bool mine(const std::vector<std::int32_t>& vs) const {
    for (auto v : vs)
      if (!mine(v)) return false;
    return true;
  }

  static constexpr double kLongEdge = 4.0 / 3, kShortRemesh = 0.8;  // remeshing's bounds, shares of the target
  struct Edge {
    double key;  // remeshing's order
    std::int32_t a, b;
    bool operator<(const Edge& o) const { return key != o.key ? key < o.key : a != o.a ? a < o.a : b < o.b; }
  };
  std::vector<Edge> edges_;
  // The valence a vertex's triangles have in a regular mesh: 6 inside, 4 on a boundary loop.
  int valenceExcess(std::int32_t v, int change) const {
    return std::abs(int(around_[std::size_t(v)].size()) + (st_.boundary[std::size_t(v)] ? 1 : 0) + change - (st_.boundary[std::size_t(v)] ? 4 : 6));
  }

  std::int32_t faceOf(std::int32_t k) const { return m_.triangle_face.empty() ? 0 : m_.triangle_face[std::size_t(k)]; }
  // The triangle whose edge runs from a to b, or −1.
  std::int32_t triangleWith(std::int32_t a, std::int32_t b) const {
    for (auto k : around_[std::size_t(a)]) {
      const auto& t = m_.triangles[std::size_t(k)];
      for (int i = 0; i < 3; ++i)
        if (t[std::size_t(i)] == a && t[std::size_t((i + 1) % 3)] == b) return k;
    }
    return -1;
  }

  // Splits edge a–b of (a, b, c) and (b, a, d) at its midpoint x (the pair's volume stays; moved
  // out to its ends' offset from the wall, a 125-terminal tree gained 0.17 %), if no new triangle
  // gets an angle below the floor (or below the smallest it replaces) or strays from the
  // surface, and nothing nearby is cut. Appends x and two triangles.
  bool split(std::int32_t a, std::int32_t b) {
    const std::int32_t k1 = triangleWith(a, b), k2 = triangleWith(b, a);
    if (k1 < 0 || k2 < 0 || faceOf(k1) != 0 || faceOf(k2) != 0) return false;
    const std::int32_t tree = m_.triangle_tree[std::size_t(k1)];
    if (m_.triangle_tree[std::size_t(k2)] != tree) return false;
    const std::int32_t c = thirdOf(k1, a, b), d = thirdOf(k2, a, b);
    if (c == d) return false;
    const Vec3 pa = m_.vertices[std::size_t(a)], pb = m_.vertices[std::size_t(b)], pc = m_.vertices[std::size_t(c)], pd = m_.vertices[std::size_t(d)];
    const Vec3 n1 = cross(pb - pa, pc - pa), n2 = cross(pa - pb, pd - pb);
    if (!(norm(n1) > 0) || !(norm(n2) > 0)) return false;
    const double step = std::min(stepOf(a), stepOf(b)), limit = o_.max_error * step;
    const Vec3 x = (pa + pb) * 0.5;
    const double error = std::abs(distance_(tree, x));
    if (!(error <= limit)) return false;
    const std::int32_t xi = std::int32_t(m_.vertices.size());
    const Vec3 after[4][3] = {{pa, x, pc}, {x, pb, pc}, {pb, x, pd}, {x, pa, pd}};
    const std::array<std::int32_t, 3> ids[4] = {{a, xi, c}, {xi, b, c}, {b, xi, d}, {xi, a, d}};
    const double floor = std::max(cos_min_angle_, std::max(smallestAngleCosine(pa, pb, pc), smallestAngleCosine(pb, pa, pd)));
    moved_.clear();
    for (int i = 0; i < 4; ++i) {
      const Vec3 ni = cross(after[i][1] - after[i][0], after[i][2] - after[i][0]), parent = i < 2 ? n1 : n2;
      if (!(norm(ni) > 0) || !(dot(ni, parent) >= cos_turn_ * norm(ni) * norm(parent))) return false;
      if (!(smallestAngleCosine(after[i][0], after[i][1], after[i][2]) <= floor)) return false;
      if (!(std::abs(distance_(tree, (after[i][0] + after[i][1] + after[i][2]) / 3.0)) <= limit)) return false;
      moved_.push_back({ids[i], {after[i][0], after[i][1], after[i][2]}});
    }
    if (cutsNear({a, b, c, d}, [&](const std::array<std::int32_t, 3>&, std::int32_t k) { return k == k1 || k == k2; })) return false;
    // x, and the triangles (x, b, c) and (x, a, d) after k1 = (a, x, c) and k2 = (b, x, d).
    const std::int32_t k3 = st_.addTriangle(ids[1], tree), k4 = st_.addTriangle(ids[3], tree);
    for (auto& v : m_.triangles[std::size_t(k1)])
      if (v == b) v = xi;
    for (auto& v : m_.triangles[std::size_t(k2)])
      if (v == a) v = xi;
    Quadric q;
    for (const auto& t : after) q.addTriangle(t[0], t[1], t[2]);
    st_.addVertex(x, float(step), mine_, {k1, k3, k2, k4}, q);
    dropTriangle(a, k2), dropTriangle(b, k1);
    around_[std::size_t(a)].push_back(k4);
    around_[std::size_t(b)].push_back(k3);
    around_[std::size_t(c)].push_back(k3);
    around_[std::size_t(d)].push_back(k4);
    largest_error = std::max(largest_error, error);
    return true;
  }

  // Triangle k's vertex other than a and b.
  std::int32_t thirdOf(std::int32_t k, std::int32_t a, std::int32_t b) const {
    const auto& t = m_.triangles[std::size_t(k)];
    return t[0] != a && t[0] != b ? t[0] : t[1] != a && t[1] != b ? t[1] : t[2];
  }
  // Triangle k no longer at vertex v.
  void dropTriangle(std::int32_t v, std::int32_t k) {
    auto& list = around_[std::size_t(v)];
    list.erase(std::find(list.begin(), list.end(), k));
  }

  // The triangle other than k with the edge a–b, or −1.
  std::int32_t across(std::int32_t k, std::int32_t a, std::int32_t b) const {
    for (auto o : around_[std::size_t(a)]) {
      const auto& t = m_.triangles[std::size_t(o)];
      if (o != k && (t[0] == b || t[1] == b || t[2] == b)) return o;
    }
    return -1;
  }

  // Flips edge a–b of triangle k = (a, b, c) and its neighbour (b, a, d) into (c, a, d) and
  // (d, b, c) if that raises their smallest angle, neither turns by more than the bound from
  // either old one, the centroids stay near the surface and nothing nearby is cut. A cap (k with
  // c nearly on a–b) has no normal to speak of: its flip is judged against the neighbour's alone,
  // and may cross a crease (the volume it moves is the cap's area times the crease's rise).
  // `by_valence` (remeshing; the caller judged the valences): the smallest angle need only stay
  // above the floor or where it was.
  bool flip(std::int32_t k1, std::int32_t a, std::int32_t b, bool cap = false, bool by_valence = false) {
    const std::int32_t k2 = across(k1, a, b);
    if (k2 < 0) return false;
    if (!m_.triangle_face.empty() && (m_.triangle_face[std::size_t(k1)] != 0 || m_.triangle_face[std::size_t(k2)] != 0)) return false;
    const std::int32_t c = thirdOf(k1, a, b), d = thirdOf(k2, a, b);
    if (!mine(a) || !mine(b) || !mine(c) || !mine(d)) return false;
    if (c == d || across(-1, c, d) >= 0) return false;  // the new edge exists already
    const Vec3 pa = m_.vertices[std::size_t(a)], pb = m_.vertices[std::size_t(b)], pc = m_.vertices[std::size_t(c)], pd = m_.vertices[std::size_t(d)];
    // The smallest angle must grow (by a margin: no flipping back and forth).
    const double old_cos = std::max(smallestAngleCosine(pa, pb, pc), smallestAngleCosine(pb, pa, pd));
    const double new_cos = std::max(smallestAngleCosine(pc, pa, pd), smallestAngleCosine(pd, pb, pc));
    if (by_valence ? !(new_cos <= std::max(cos_min_angle_, old_cos)) : !(new_cos < old_cos - 1e-3)) return false;
    const Vec3 n1 = cross(pb - pa, pc - pa), n2 = cross(pa - pb, pd - pb), m1 = cross(pa - pc, pd - pc), m2 = cross(pb - pd, pc - pd);
    // Nearly flat pairs only: a flip across a crease moves the surface (and, on convex vessels,
    // always inwards: it would take volume).
    if (!cap && !(dot(n1, n2) >= kFlatFlip * norm(n1) * norm(n2))) return false;
    const auto turns = [&](const Vec3& nold) {
      return !(dot(m1, nold) >= cos_turn_ * norm(m1) * norm(nold)) || !(dot(m2, nold) >= cos_turn_ * norm(m2) * norm(nold));
    };
    if ((!cap && turns(n1)) || turns(n2)) return false;
    const std::int32_t tree = m_.triangle_tree[std::size_t(k1)];
    const double limit = o_.max_error * std::min({stepOf(a), stepOf(b), stepOf(c), stepOf(d)});
    if (!(std::abs(distance_(tree, (pc + pa + pd) / 3.0)) <= limit) || !(std::abs(distance_(tree, (pd + pb + pc) / 3.0)) <= limit)) return false;
    moved_.clear();
    moved_.push_back({{c, a, d}, {pc, pa, pd}});
    moved_.push_back({{d, b, c}, {pd, pb, pc}});
    if (cutsNear({a, b, c, d}, [&](const std::array<std::int32_t, 3>&, std::int32_t k) { return k == k1 || k == k2; })) return false;
    m_.triangles[std::size_t(k1)] = {c, a, d};
    m_.triangles[std::size_t(k2)] = {d, b, c};
    dropTriangle(a, k2);
    dropTriangle(b, k1);
    around_[std::size_t(c)].push_back(k2);
    around_[std::size_t(d)].push_back(k1);
    return true;
  }
  void neighbours(std::int32_t v, std::vector<std::int32_t>& out) const {
    out.clear();
    for (auto k : around_[std::size_t(v)])
      for (auto x : m_.triangles[std::size_t(k)])
        if (x != v) out.push_back(x);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  // Where u and v would meet: a locked vertex stays; else the quadric's minimum under the
  // constraint that the enclosed volume stays (linear in the position: Lindstrom and Turk), with
  // a faint pull to the edge's midpoint so that flat and cylindrical patches (a line or plane
  // of minima) have one answer.
  Vec3 placement(std::int32_t u, std::int32_t v, const Quadric& q) const {
    const Vec3 pu = m_.vertices[std::size_t(u)], pv = m_.vertices[std::size_t(v)], mid = (pu + pv) * 0.5;
    if (locked_[std::size_t(u)]) return pu;
    if (locked_[std::size_t(v)]) return pv;
    // 6 × volume of the triangles around u and v (as cones from the origin) = Σ det, and the
    // same after the collapse = w · g.
    double six_volume = 0;
    Vec3 g(0, 0, 0);
    for (const std::int32_t end : {u, v})
      for (auto k : around_[std::size_t(end)]) {
        const auto& t = m_.triangles[std::size_t(k)];
        const bool has_u = t[0] == u || t[1] == u || t[2] == u, has_v = t[0] == v || t[1] == v || t[2] == v;
        if (end == v && has_u) continue;  // counted from u
        const Vec3 a = m_.vertices[std::size_t(t[0])], b = m_.vertices[std::size_t(t[1])], c = m_.vertices[std::size_t(t[2])];
        six_volume += dot(a, cross(b, c));
        if (has_u && has_v) continue;  // collapses away
        const int i = t[0] == end ? 0 : t[1] == end ? 1 : 2;
        g += cross(m_.vertices[std::size_t(t[std::size_t((i + 1) % 3)])], m_.vertices[std::size_t(t[std::size_t((i + 2) % 3)])]);
      }
    const double alpha = 1e-3 * (q.xx + q.yy + q.zz) / 3 + 1e-300;
    Vec3 w0, y;
    if (!q.solve(alpha, Vec3(-q.xw, -q.yw, -q.zw) + mid * alpha, w0)) return mid;
    if (!(dot(g, g) > 0) || !q.solve(alpha, g, y) || !(std::abs(dot(g, y)) > 0)) return w0;
    return w0 + y * ((six_volume - dot(g, w0)) / dot(g, y));
  }

  void push(std::int32_t u, std::int32_t v) {
    if (locked_[std::size_t(u)] && locked_[std::size_t(v)]) return;
    // Both ends and every vertex placement() reads in this worker's block.
    if (!ringMine(u) || !ringMine(v)) return;
    Quadric q = quadric_[std::size_t(u)];
    q += quadric_[std::size_t(v)];
    const Vec3 w = placement(u, v, q);
    queue_.push({std::max(0.0, q(w)), u, v, version_[std::size_t(u)], version_[std::size_t(v)]});
  }

  // The checks of a collapse of edge u–v into u at w; `error`: |distance| at w.
  // `max_edge` > 0 (remeshing): no edge at w longer than that share of its ends' step.
  // Remeshing, an edge of a boundary loop (its one triangle) collapses too, into its survivor.
  bool allowed(std::int32_t u, std::int32_t v, Vec3& w, double& error, double max_edge = 0) {
    const bool loop_edge = max_edge > 0 && st_.boundary[std::size_t(u)] && st_.boundary[std::size_t(v)];
    if (locked_[std::size_t(u)] && locked_[std::size_t(v)] && !loop_edge && !joinsCapVertices(u, v)) return false;
    // The edge's two triangles and their third vertices.
    std::int32_t shared[2], opposite[2];
    int ns = 0;
    for (auto k : around_[std::size_t(u)]) {
      const auto& t = m_.triangles[std::size_t(k)];
      if (t[0] != v && t[1] != v && t[2] != v) continue;
      if (ns == 2) return false;
      shared[ns] = k;
      opposite[ns++] = t[0] != u && t[0] != v ? t[0] : t[1] != u && t[1] != v ? t[1] : t[2];
    }
    if (ns != (loop_edge ? 1 : 2) || (ns == 2 && opposite[0] == opposite[1])) return false;
    if (ns == 1) shared[1] = shared[0], opposite[1] = opposite[0];
    for (auto o : opposite)
      if (around_[std::size_t(o)].size() <= (st_.boundary[std::size_t(o)] ? 1u : 3u)) return false;  // keeps a triangle; inside, three
    // Link condition: u and v have no other common neighbour.
    neighbours(u, ring_u_);
    neighbours(v, ring_v_);
    if (!mine(ring_u_) || !mine(ring_v_)) return false;
    int common = 0;
    for (std::size_t i = 0, j = 0; i < ring_u_.size() && j < ring_v_.size();) {
      if (ring_u_[i] < ring_v_[j])
        ++i;
      else if (ring_v_[j] < ring_u_[i])
        ++j;
      else
        ++common, ++i, ++j;
    }
    if (common != ns) return false;
    Quadric q = quadric_[std::size_t(u)];
    q += quadric_[std::size_t(v)];
    w = placement(u, v, q);
    const std::int32_t tree = m_.triangle_tree[std::size_t(shared[0])];
    const double step = std::min(stepOf(u), stepOf(v)), limit = o_.max_error * step;
    error = std::abs(distance_(tree, w));
    if (!(error <= limit)) return false;
    if (max_edge > 0)
      for (const auto* ring : {&ring_u_, &ring_v_})
        for (auto x : *ring)
          if (x != u && x != v && distance(w, m_.vertices[std::size_t(x)]) > max_edge * std::min(step, stepOf(x))) return false;
    // The triangles that stay, moved: no flip, no sharp turn, no new angle below the floor (or
    // below the smallest of those it replaces), near the surface.
    double old_cos = -1;
    for (const std::int32_t end : {u, v})
      for (auto k : around_[std::size_t(end)]) {
        const auto& t = m_.triangles[std::size_t(k)];
        old_cos =
            std::max(old_cos, smallestAngleCosine(m_.vertices[std::size_t(t[0])], m_.vertices[std::size_t(t[1])], m_.vertices[std::size_t(t[2])]));
      }
    const double floor = std::max(cos_min_angle_, old_cos);  // as a cosine
    const Vec3 star = starNormal(u, v);
    moved_.clear();
    for (const std::int32_t end : {u, v})
      for (auto k : around_[std::size_t(end)]) {
        if (k == shared[0] || k == shared[1]) continue;
        const auto& t = m_.triangles[std::size_t(k)];
        Vec3 before[3], after[3];
        for (int i = 0; i < 3; ++i) {
          before[i] = m_.vertices[std::size_t(t[std::size_t(i)])];
          after[i] = t[std::size_t(i)] == u || t[std::size_t(i)] == v ? w : before[i];
        }
        if (turnsOver(before, after, star)) return false;
        if (!(smallestAngleCosine(after[0], after[1], after[2]) <= floor)) return false;
        if (!(std::abs(distance_(tree, (after[0] + after[1] + after[2]) / 3.0)) <= limit)) return false;
        std::array<std::int32_t, 3> ids = t;
        for (auto& x : ids)
          if (x == v) x = u;
        moved_.push_back({ids, {after[0], after[1], after[2]}});
      }
    seeds_ = ring_u_;
    seeds_.insert(seeds_.end(), ring_v_.begin(), ring_v_.end());
    const auto has = [](const std::array<std::int32_t, 3>& t, std::int32_t x) { return t[0] == x || t[1] == x || t[2] == x; };
    return !cutsNear(seeds_, [&](const std::array<std::int32_t, 3>& t, std::int32_t) { return has(t, u) || has(t, v); });
  }

  // Whether the moved triangles (moved_) cut each other or a triangle near them: every triangle
  // at a seed vertex and, outwards from those across their vertices, every one whose box meets
  // the moved ones' (a long moved triangle reaches past its ring); `replaced(t, k)` names the
  // triangles the change takes away. Reaching out of the block counts as a cut: not in this pass.
  template <class Replaced>
  bool cutsNear(const std::vector<std::int32_t>& seeds, const Replaced& replaced) {
    Vec3 lo = moved_[0].at[0], hi = lo;
    for (const auto& mv : moved_)
      for (const auto& p : mv.at) lo = lower(lo, p), hi = upper(hi, p);
    const std::uint64_t mark = stamp();
    nearby_.clear();
    bool outside = false;
    const auto visit = [&](std::int32_t x) {
      for (auto k : around_[std::size_t(x)]) {
        const auto& t = m_.triangles[std::size_t(k)];
        if (st_.visited[std::size_t(k)] == mark || replaced(t, k)) continue;
        if (!mine(t[0]) || !mine(t[1]) || !mine(t[2])) return outside = true, void();
        st_.visited[std::size_t(k)] = mark;
        nearby_.push_back(k);
      }
    };
    for (auto x : seeds)
      if (visit(x), outside) return true;
    close_.clear();
    for (std::size_t i = 0; i < nearby_.size(); ++i) {
      const auto t = m_.triangles[std::size_t(nearby_[i])];
      Vec3 tlo, thi;
      triangleBox(m_.vertices[std::size_t(t[0])], m_.vertices[std::size_t(t[1])], m_.vertices[std::size_t(t[2])], tlo, thi);
      if (boxesApart(tlo, thi, lo, hi)) continue;
      // Only these can meet a moved triangle (each moved one lies in that box).
      close_.push_back({nearby_[i], tlo, thi});
      for (auto x : t)
        if (visit(x), outside) return true;
    }
    return cutsNearby();
  }
  bool cutsNear(std::initializer_list<std::int32_t> seeds, const auto& replaced) {
    seeds_.assign(seeds.begin(), seeds.end());
    return cutsNear(seeds_, replaced);
  }

  // moved_ against each other and against close_ (boxes first).
  bool cutsNearby() {
    for (std::size_t i = 0; i < moved_.size(); ++i) {
      Vec3 lo, hi;
      triangleBox(moved_[i].at[0], moved_[i].at[1], moved_[i].at[2], lo, hi);
      for (std::size_t j = i + 1; j < moved_.size(); ++j)
        if (intersect(moved_[i].ids, moved_[i].at, moved_[j].ids, moved_[j].at)) return true;
      for (const auto& c : close_) {
        if (boxesApart(c.lo, c.hi, lo, hi)) continue;
        const auto& t = m_.triangles[std::size_t(c.k)];
        const Vec3 at[3] = {m_.vertices[std::size_t(t[0])], m_.vertices[std::size_t(t[1])], m_.vertices[std::size_t(t[2])]};
        if (intersect(moved_[i].ids, moved_[i].at, t, at)) return true;
      }
    }
    return false;
  }

  double stepOf(std::int32_t v) const { return m_.vertex_step.empty() ? INFINITY : double(m_.vertex_step[std::size_t(v)]); }

  void collapse(std::int32_t u, std::int32_t v, const Vec3& w) {
    m_.vertices[std::size_t(u)] = w;
    quadric_[std::size_t(u)] += quadric_[std::size_t(v)];
    if (!m_.vertex_step.empty()) m_.vertex_step[std::size_t(u)] = std::min(m_.vertex_step[std::size_t(u)], m_.vertex_step[std::size_t(v)]);
    locked_[std::size_t(u)] |= locked_[std::size_t(v)];
    for (auto k : around_[std::size_t(v)]) {
      auto& t = m_.triangles[std::size_t(k)];
      if (t[0] == u || t[1] == u || t[2] == u) {
        triangle_alive_[std::size_t(k)] = 0;
        ++removed;
        for (auto x : t)
          if (x != v) dropTriangle(x, k);
      } else {
        for (auto& x : t)
          if (x == v) x = u;
        around_[std::size_t(u)].push_back(k);
      }
    }
    std::vector<std::int32_t>().swap(around_[std::size_t(v)]);
    vertex_alive_[std::size_t(v)] = 0;
    ++version_[std::size_t(u)];
    ++version_[std::size_t(v)];
  }

  State& st_;
  SurfaceMesh& m_;
  const DecimateOptions& o_;
  const std::function<double(std::int32_t, const Vec3&)>& distance_;
  std::vector<std::vector<std::int32_t>>& around_;
  std::vector<Quadric>& quadric_;
  std::vector<std::uint32_t>& version_;
  std::vector<char>&vertex_alive_, &locked_, &triangle_alive_;
  const std::vector<std::int64_t>& block_;
  const std::int64_t mine_;
  std::uint64_t changes_ = 0;
  mutable bool blocked_ = false;  // a check reached out of the block
  std::priority_queue<Candidate> queue_;
  std::vector<std::int32_t> ring_u_, ring_v_, nearby_, seeds_, touched_, work_;
  struct Moved {
    std::array<std::int32_t, 3> ids;
    Vec3 at[3];
  };
  std::vector<Moved> moved_;
  struct Boxed {
    std::int32_t k;
    Vec3 lo, hi;
  };
  std::vector<Boxed> close_;  // the nearby triangles whose box meets the box of the moved ones
  double cos_turn_ = 0, cos_min_angle_ = 1, cos_sliver_ = 1, cos_obtuse_ = -1;
};

// Blocks: cubes of kBlockSteps median steps, shifted by half a block in odd passes so that what
// one pass leaves at block borders the next has inside.
constexpr double kBlockSteps = 128;
constexpr int kRounds = 4;

// Alive triangles with all three vertices in one block, grouped by block (blocks and triangles
// in ascending order); for a repair pass, only those it takes on (needsRepair; a sliver pass
// with at_fixed_only, only those with a fixed vertex).
std::vector<std::vector<std::int32_t>> partition(State& st, double size, double shift, Pass kind, double cos_bound) {
  const auto& m = st.m;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m.vertices.size(), 8192), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t v = r.begin(); v != r.end(); ++v) {
      const Vec3& p = m.vertices[v];
      const auto c = [&](double x) { return std::int64_t(std::floor(x / size + shift)) & 0x1fffff; };
      st.block[v] = (c(p.x) << 42) | (c(p.y) << 21) | c(p.z);
    }
  });
  std::vector<std::pair<std::int64_t, std::int32_t>> keyed;
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    if (!st.triangle_alive[k]) continue;
    const auto& t = m.triangles[k];
    const auto b = st.block[std::size_t(t[0])];
    if (st.block[std::size_t(t[1])] != b || st.block[std::size_t(t[2])] != b) continue;
    if ((kind == Pass::sliver || kind == Pass::obtuse) && !needsRepair(m, t, kind, cos_bound)) continue;
    if (kind == Pass::sliver && st.at_fixed_only && !st.locked[std::size_t(t[0])] && !st.locked[std::size_t(t[1])] && !st.locked[std::size_t(t[2])])
      continue;
    keyed.emplace_back(b, std::int32_t(k));
  }
  tbb::parallel_sort(keyed.begin(), keyed.end());
  std::vector<std::vector<std::int32_t>> blocks;
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    if (i == 0 || keyed[i].first != keyed[i - 1].first) blocks.emplace_back();
    blocks.back().push_back(keyed[i].second);
  }
  return blocks;
}

// One pass of `kind` over blocks of `size` mm shifted by `shift` blocks, its blocks in parallel;
// the collapses and flips it made.
std::int64_t runPass(State& st, DecimateReport& rep, double size, double shift, Pass kind) {
  const double cos_bound = std::cos((kind == Pass::obtuse ? st.o.obtuse_deg : st.o.sliver_deg) * std::numbers::pi / 180);
  const auto blocks = partition(st, size, shift, kind, cos_bound);
  ++st.pass;
  if ((kind == Pass::sliver || kind == Pass::obtuse) && st.changed.empty())
    st.changed.assign(st.m.vertices.size(), 0), st.failed.assign(st.m.triangles.size(), 0);
  std::vector<Worker> workers;
  workers.reserve(blocks.size());
  for (const auto& b : blocks) workers.emplace_back(st, st.block[std::size_t(st.m.triangles[std::size_t(b.front())][0])]);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const auto* first = blocks[i].data();
      const auto* last = first + blocks[i].size();
      if (kind == Pass::flip)
        workers[i].flipPass(first, last);
      else if (kind == Pass::collapse)
        workers[i].collapsePass(first, last);
      else
        workers[i].repairPass(first, last, kind);
    }
  });
  std::int64_t made = 0;
  for (const auto& w : workers) {
    made += w.collapses + w.flips + w.moves;
    rep.collapses += w.collapses, rep.flips += w.flips, rep.moves += w.moves, rep.after -= w.removed;
    rep.largest_error_mm = std::max(rep.largest_error_mm, w.largest_error);
  }
  return made;
}

// The slivers' passes, then (with obtuse_deg) the obtuse triangles', each in both partitions.
void repairPasses(State& st, DecimateReport& rep, double size) {
  for (const Pass kind : {Pass::sliver, Pass::obtuse})
    if (kind == Pass::sliver || st.o.obtuse_deg > 0)
      for (double shift : {0.0, 0.5}) runPass(st, rep, size, shift, kind);
}

// Blocks of kBlockSteps median steps (an eighth of the mesh's extent without steps).
double blockSize(const SurfaceMesh& m) {
  std::vector<float> steps = m.vertex_step;
  if (!steps.empty()) {
    std::nth_element(steps.begin(), steps.begin() + std::ptrdiff_t(steps.size() / 2), steps.end());
    return kBlockSteps * double(steps[steps.size() / 2]);
  }
  Vec3 lo = m.vertices[0], hi = lo;
  for (const auto& p : m.vertices) lo = componentMin(lo, p), hi = componentMax(hi, p);
  return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-9}) / 8;
}

}  // namespace

DecimateReport decimate(SurfaceMesh& m, const DecimateOptions& o, const std::function<double(std::int32_t, const Vec3&)>& distance,
                        std::vector<std::int32_t>* renumber) {
  DecimateReport rep;
  rep.before = rep.after = std::int64_t(m.triangles.size());
  if (m.triangles.empty()) return rep;
  State st(m, o, distance);
  const double size = blockSize(m);
  // Collapses in both partitions, then flips; rounds until a round collapses nothing; then the
  // slivers left.
  for (int round = 0; round < kRounds; ++round) {
    std::int64_t collapsed = 0;
    for (double shift : {0.0, 0.5}) collapsed += runPass(st, rep, size, shift, Pass::collapse);
    if (round > 0 && collapsed == 0) break;
    runPass(st, rep, size, round % 2 ? 0.5 : 0.0, Pass::flip);
  }
  if (o.sliver_deg > 0) repairPasses(st, rep, size);
  st.compact(renumber);
  return rep;
}

DecimateReport remeshIsotropic(SurfaceMesh& m, const DecimateOptions& o, double target, int rounds,
                               const std::function<double(std::int32_t, const Vec3&)>& distance, std::vector<std::int32_t>* renumber) {
  DecimateReport rep;
  rep.before = rep.after = std::int64_t(m.triangles.size());
  if (m.triangles.empty() || m.vertex_step.empty()) return rep;
  State st(m, o, distance);  // every vertex in block 0: one worker
  Worker w(st, 0);
  for (int round = 0; round < rounds; ++round) w.remeshRound(target);
  rep.collapses = w.collapses, rep.flips = w.flips, rep.moves = w.moves, rep.splits = w.splits;
  rep.largest_error_mm = w.largest_error;
  if (o.sliver_deg > 0) repairPasses(st, rep, INFINITY);
  st.compact(renumber);
  rep.after = std::int64_t(m.triangles.size());
  return rep;
}

DecimateReport repairSlivers(SurfaceMesh& m, const DecimateOptions& o, const std::function<double(std::int32_t, const Vec3&)>& distance,
                             std::vector<std::int32_t>* renumber, bool at_fixed_only) {
  DecimateReport rep;
  rep.before = rep.after = std::int64_t(m.triangles.size());
  if (m.triangles.empty()) return rep;
  State st(m, o, distance);
  st.at_fixed_only = at_fixed_only;
  const double size = blockSize(m);
  repairPasses(st, rep, size);
  st.compact(renumber);
  return rep;
}

}  // namespace angiosynth
