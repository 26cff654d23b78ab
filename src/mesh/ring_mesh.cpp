#include "mesh/ring_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace angiosynth {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// Angle of p around the axis through c along u, from e1 towards e2 = u × e1, in [0, 2π).
double angleAround(const Vec3& p, const Vec3& c, const Vec3& e1, const Vec3& e2) {
  const double a = std::atan2(dot(p - c, e2), dot(p - c, e1));
  return a < 0 ? a + kTwoPi : a;
}

// A contoured loop may step back by a hair where two of its vertices sit at one angle (a cut
// point next to a vertex the volume restoration slid); the tube's triangle on that edge would
// face inwards. Such an edge, at most kHair of the radius long, is collapsed into its first
// vertex (the one contour triangle on it goes) when that keeps the surface a manifold and turns
// no triangle over, else into its second (both lie in the plane). True when the loop's angles
// then rise all the way round.
bool makeStarShaped(SurfaceMesh& m, std::vector<std::int32_t>& loop, std::unordered_map<std::int32_t, std::vector<std::int32_t>>& around,
                    std::vector<char>& keep, const Vec3& centre, const Vec3& u, double r) {
  constexpr double kHair = 0.05;
  const auto rises = [&](std::int32_t a, std::int32_t b) {
    return dot(cross(m.vertices[std::size_t(a)] - centre, m.vertices[std::size_t(b)] - centre), u) > 0;
  };
  // Loop edges shorter than this go too (where they can): the triangles on either side would be
  // slivers (a cut point beside a vertex just off the plane), and single-precision formats
  // could round their ends onto one point (8 of its units at the loop's coordinates).
  constexpr double kShortLoopEdge = 0.02;  // radii: a tenth of a contoured loop's spacing at 3 samples across
  const double extent = std::max({std::abs(centre.x), std::abs(centre.y), std::abs(centre.z)}) + 2 * r;
  const double shortest = std::max(kShortLoopEdge * r, 8 * double(std::numeric_limits<float>::epsilon()) * extent);
  // Moves loop vertex q onto its neighbour p (their triangle goes) where the link condition
  // holds and no triangle turns over.
  const auto collapse = [&](std::int32_t q, std::int32_t p) {
    auto& tp = around[p];
    auto& tq = around[q];
    std::vector<std::int32_t> shared, others;
    const auto has = [&](std::int32_t t, std::int32_t x) {
      const auto& tri = m.triangles[std::size_t(t)];
      return tri[0] == x || tri[1] == x || tri[2] == x;
    };
    for (auto t : tq)
      if (keep[std::size_t(t)]) (has(t, p) ? shared : others).push_back(t);
    if (shared.size() != 1) return false;
    // Link condition: the vertices next to both are the shared triangle's third one only.
    std::vector<std::int32_t> np, nq;
    for (auto t : tp)
      if (keep[std::size_t(t)])
        for (auto x : m.triangles[std::size_t(t)]) np.push_back(x);
    for (auto t : tq)
      if (keep[std::size_t(t)])
        for (auto x : m.triangles[std::size_t(t)]) nq.push_back(x);
    std::sort(np.begin(), np.end());
    np.erase(std::unique(np.begin(), np.end()), np.end());
    std::sort(nq.begin(), nq.end());
    nq.erase(std::unique(nq.begin(), nq.end()), nq.end());
    std::vector<std::int32_t> common;
    std::set_intersection(np.begin(), np.end(), nq.begin(), nq.end(), std::back_inserter(common));
    if (common.size() != 3) return false;  // p, q and the shared triangle's third vertex
    // No triangle of q's turns over when q moves onto p.
    for (auto t : others) {
      auto tri = m.triangles[std::size_t(t)];
      const auto normal = [&](const std::array<std::int32_t, 3>& x) {
        return cross(m.vertices[std::size_t(x[1])] - m.vertices[std::size_t(x[0])], m.vertices[std::size_t(x[2])] - m.vertices[std::size_t(x[0])]);
      };
      const Vec3 before = normal(tri);
      for (auto& x : tri)
        if (x == q) x = p;
      if (!(dot(before, normal(tri)) > 0)) return false;
    }
    keep[std::size_t(shared[0])] = 0;
    for (auto t : others) {
      for (auto& x : m.triangles[std::size_t(t)])
        if (x == q) x = p;
      tp.push_back(t);
    }
    return true;
  };
  for (std::size_t i = 0; i < loop.size() && loop.size() >= 3;) {
    const auto p = loop[i], q = loop[(i + 1) % loop.size()];
    const double length = distance(m.vertices[std::size_t(p)], m.vertices[std::size_t(q)]);
    const bool rising = rises(p, q);
    if (rising && !(length < shortest)) {
      ++i;
      continue;
    }
    if (!rising && !(length <= kHair * r)) return false;
    std::size_t gone = (i + 1) % loop.size(), kept = i;
    if (!collapse(q, p)) {
      if (rising) {
        ++i;  // short, but it stays
        continue;
      }
      if (!collapse(p, q)) return false;
      std::swap(gone, kept);
    }
    loop.erase(loop.begin() + std::ptrdiff_t(gone));
    if (kept > gone) --kept;      // the survivor moved down one
    i = kept > 0 ? kept - 1 : 0;  // the step before it may have changed
  }
  for (std::size_t i = 0; i < loop.size(); ++i)
    if (!rises(loop[i], loop[(i + 1) % loop.size()])) return false;
  return loop.size() >= 3;
}

}  // namespace

std::vector<std::vector<std::int32_t>> boundaryLoops(const SurfaceMesh& m, const std::vector<char>& on) {
  std::vector<std::pair<std::int64_t, std::int64_t>> edges;  // (min·2^32 + max, from·2^32 + to)
  for (const auto& t : m.triangles)
    for (int i = 0; i < 3; ++i) {
      const std::int64_t a = t[std::size_t(i)], b = t[std::size_t((i + 1) % 3)];
      if (on[std::size_t(a)] && on[std::size_t(b)]) edges.emplace_back((std::min(a, b) << 32) | std::max(a, b), (a << 32) | b);
    }
  std::sort(edges.begin(), edges.end());
  std::vector<std::pair<std::int32_t, std::int32_t>> next;  // from → to of edges used once
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].first == edges[i].first) ++j;
    if (j - i == 1) next.emplace_back(std::int32_t(edges[i].second >> 32), std::int32_t(edges[i].second & 0xffffffff));
    i = j;
  }
  std::sort(next.begin(), next.end());
  const auto from = [&](std::int32_t v) {
    const auto it = std::lower_bound(next.begin(), next.end(), std::make_pair(v, std::int32_t(-1)));
    const bool one = it != next.end() && it->first == v && (it + 1 == next.end() || (it + 1)->first != v);
    return one ? std::size_t(it - next.begin()) : next.size();
  };
  std::vector<char> used(next.size(), 0);
  std::vector<std::vector<std::int32_t>> loops;
  for (std::size_t i = 0; i < next.size(); ++i) {
    if (used[i]) continue;
    std::vector<std::int32_t> loop;
    bool ok = true;
    for (std::size_t at = i;;) {
      used[at] = 1;
      loop.push_back(next[at].first);
      at = from(next[at].second);
      if (at == next.size()) {
        ok = false;
        break;
      }
      if (at == i) break;
      if (used[at]) {
        ok = false;
        break;
      }
    }
    if (ok) loops.push_back(std::move(loop));
  }
  return loops;
}

// e1 ⟂ u, and e2 = u × e1: (e1, e2, u) is right-handed.
void frameOf(const Vec3& u, Vec3& e1, Vec3& e2) {
  const Vec3 pick = std::abs(u.x) < 0.6 ? Vec3(1, 0, 0) : std::abs(u.y) < 0.6 ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
  e1 = unit(pick - u * dot(pick, u));
  e2 = cross(u, e1);
}

namespace {

// A point lies in an end's plane: on it, within two radii of its centre.
bool inPlane(const Vec3& p, const VesselEnd& e) {
  return std::abs(dot(p - e.centre, e.normal)) <= 1e-9 * e.radius && distance(p, e.centre) < 2 * e.radius;
}

// The planes binned on cubes of their largest diameter, each in the 27 around its centre's
// (neighbours by index: cubes found from shifted points could skip one to rounding): the planes
// a point may lie in (inPlane) are those of its cube, in ascending order.
class PlaneBins {
 public:
  explicit PlaneBins(const std::vector<VesselEnd>& planes) {
    for (const auto& e : planes) g_ = std::max(g_, 2 * e.radius);
    for (std::size_t k = 0; k < planes.size(); ++k) {
      const auto c = cube(planes[k].centre);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) bins_[key({c[0] + dx, c[1] + dy, c[2] + dz})].push_back(std::int32_t(k));
    }
  }
  const std::vector<std::int32_t>* near(const Vec3& p) const {
    const auto it = bins_.find(key(cube(p)));
    return it == bins_.end() ? nullptr : &it->second;
  }

 private:
  std::array<std::int64_t, 3> cube(const Vec3& p) const {
    return {std::int64_t(std::floor(p.x / g_)), std::int64_t(std::floor(p.y / g_)), std::int64_t(std::floor(p.z / g_))};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    return (std::uint64_t(c[0] & 0x1fffff) << 42) | (std::uint64_t(c[1] & 0x1fffff) << 21) | std::uint64_t(c[2] & 0x1fffff);
  }
  double g_ = 0;
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> bins_;
};

}  // namespace

std::vector<char> verticesInPlanes(const SurfaceMesh& m, const std::vector<VesselEnd>& planes) {
  std::vector<char> on(m.vertices.size(), 0);
  if (planes.empty()) return on;
  const PlaneBins bins(planes);
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    if (const auto* near = bins.near(m.vertices[v]))
      for (auto k : *near)
        if (inPlane(m.vertices[v], planes[std::size_t(k)])) {
          on[v] = 1;
          break;
        }
  return on;
}

void zipRings(SurfaceMesh& m, const Vec3& axis, const Vec3& u, const std::vector<std::int32_t>& A, const std::vector<std::int32_t>& B,
              std::int32_t tree, std::int32_t face, bool by_shape) {
  Vec3 e1, e2;
  frameOf(u, e1, e2);
  // Angles around the axis (not the ring's centroid: a contoured loop is star-shaped around the
  // axis, checked), from the vertex at the smallest, each the last plus its turn in (−π, π].
  const auto unwrap = [&](const std::vector<std::int32_t>& ring, std::vector<double>& ang) {
    const std::size_t n = ring.size();
    const Vec3 c = axis + u * dot(m.vertices[std::size_t(ring[0])] - axis, u);
    std::size_t first = 0;
    std::vector<double> raw(n);
    for (std::size_t i = 0; i < n; ++i) {
      raw[i] = angleAround(m.vertices[std::size_t(ring[i])], c, e1, e2);
      if (raw[i] < raw[first]) first = i;
    }
    ang.resize(n + 1);
    ang[0] = raw[first];
    for (std::size_t i = 1; i <= n; ++i) {
      double d = raw[(first + i) % n] - raw[(first + i - 1) % n];
      if (d <= -std::numbers::pi) d += kTwoPi;
      if (d > std::numbers::pi) d -= kTwoPi;
      ang[i] = ang[i - 1] + d;
    }
    return first;
  };
  std::vector<double> aa, ab;
  const std::size_t fa = unwrap(A, aa), fb = unwrap(B, ab), p = A.size(), q = B.size();
  const auto a = [&](std::size_t i) { return A[(fa + i) % p]; };
  const auto b = [&](std::size_t j) { return B[(fb + j) % q]; };
  std::size_t i = 0, j = 0;
  while (i < p || j < q) {
    bool advance_a = j == q || (i < p && aa[i + 1] <= ab[j + 1]);
    if (by_shape && i < p && j < q) {
      // Either way the strip stays a strip (the diagonals a(i)–b(j) never cross): the shorter
      // diagonal (Christiansen and Sederberg).
      const double da = distance(m.vertices[std::size_t(a(i + 1))], m.vertices[std::size_t(b(j))]);
      const double db = distance(m.vertices[std::size_t(a(i))], m.vertices[std::size_t(b(j + 1))]);
      if (da != db) advance_a = da < db;
    }
    if (advance_a) {
      m.triangles.push_back({a(i), a(i + 1), b(j)});
      ++i;
    } else {
      m.triangles.push_back({a(i), b(j + 1), b(j)});
      ++j;
    }
    m.triangle_tree.push_back(tree);
    m.triangle_face.push_back(face);
  }
}

std::vector<std::vector<std::int32_t>> starLoops(SurfaceMesh& m, const std::vector<VesselEnd>& planes, const std::vector<char>& skip,
                                                 std::vector<std::vector<std::int32_t>>* bent) {
  std::vector<std::vector<std::int32_t>> out(planes.size());
  if (bent) bent->assign(planes.size(), {});
  const auto loops = boundaryLoops(m, verticesInPlanes(m, planes));
  std::vector<char> keep(m.triangles.size(), 1);
  std::unordered_map<std::int32_t, std::vector<std::int32_t>> around;  // loop vertex → its triangles
  for (const auto& loop : loops)
    for (auto p : loop) around[p];
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    for (auto p : m.triangles[t])
      if (const auto it = around.find(p); it != around.end()) it->second.push_back(std::int32_t(t));
  // Each plane's loop: the first that lies in it (found through the bins of its first vertex).
  std::vector<std::int32_t> loop_of(planes.size(), -1);
  if (!planes.empty()) {
    const PlaneBins bins(planes);
    for (std::size_t l = 0; l < loops.size(); ++l) {
      const auto* near = loops[l].empty() ? nullptr : bins.near(m.vertices[std::size_t(loops[l][0])]);
      if (!near) continue;
      for (auto k : *near) {
        if (loop_of[std::size_t(k)] >= 0 || (!skip.empty() && skip[std::size_t(k)])) continue;
        if (std::all_of(loops[l].begin(), loops[l].end(),
                        [&](std::int32_t p) { return inPlane(m.vertices[std::size_t(p)], planes[std::size_t(k)]); }))
          loop_of[std::size_t(k)] = std::int32_t(l);
      }
    }
  }
  for (std::size_t k = 0; k < planes.size(); ++k) {
    if (loop_of[k] < 0) continue;
    const auto& e = planes[k];
    const auto& loop = loops[std::size_t(loop_of[k])];
    double turn = 0;
    for (std::size_t i = 0; i < loop.size(); ++i)
      turn += dot(cross(m.vertices[std::size_t(loop[i])] - e.centre, m.vertices[std::size_t(loop[(i + 1) % loop.size()])] - e.centre), e.normal);
    std::vector<std::int32_t> ccw = loop;
    if (turn < 0) std::reverse(ccw.begin(), ccw.end());
    if (makeStarShaped(m, ccw, around, keep, e.centre, e.normal, e.radius))
      out[k] = std::move(ccw);
    else if (bent)
      (*bent)[k] = std::move(ccw);
  }
  // Drop what the repairs removed, and renumber the loops.
  std::vector<std::int32_t> renumber;
  keepTriangles(m, keep, &renumber);
  for (auto& l : out)
    for (auto& p : l) p = renumber[std::size_t(p)];
  if (bent)
    for (auto& l : *bent)
      for (auto& p : l) p = renumber[std::size_t(p)];
  return out;
}

std::vector<std::array<int, 3>> earClip(const std::vector<Vec3>& polygon, const Vec3& u, const Vec3& w) {
  const int n = int(polygon.size());
  std::vector<double> x(polygon.size()), y(polygon.size());
  for (int i = 0; i < n; ++i) x[std::size_t(i)] = dot(polygon[std::size_t(i)], u), y[std::size_t(i)] = dot(polygon[std::size_t(i)], w);
  const auto orient = [&](int a, int b, int c) {
    return (x[std::size_t(b)] - x[std::size_t(a)]) * (y[std::size_t(c)] - y[std::size_t(a)]) -
           (y[std::size_t(b)] - y[std::size_t(a)]) * (x[std::size_t(c)] - x[std::size_t(a)]);
  };
  const auto length2 = [&](int a, int b) {
    const double dx = x[std::size_t(b)] - x[std::size_t(a)], dy = y[std::size_t(b)] - y[std::size_t(a)];
    return dx * dx + dy * dy;
  };
  std::vector<int> ring(polygon.size());
  for (int i = 0; i < n; ++i) ring[std::size_t(i)] = i;
  // An ear's shape: 2√3·(twice its area) / Σ edge², 1 when equilateral, 0 when flat; −1 for no ear.
  const auto ear = [&](std::size_t i) {
    const std::size_t k = ring.size();
    const int a = ring[(i + k - 1) % k], b = ring[i], c = ring[(i + 1) % k];
    const double twice = orient(a, b, c);
    if (!(twice > 0)) return -1.0;
    for (const int p : ring)
      if (p != a && p != b && p != c && orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0) return -1.0;
    return 2 * std::sqrt(3.0) * twice / (length2(a, b) + length2(b, c) + length2(c, a));
  };
  // The roundest ear first, so that nearly straight runs of the loop are not clipped into slivers.
  std::vector<double> shape(ring.size());
  for (std::size_t i = 0; i < ring.size(); ++i) shape[i] = ear(i);
  std::vector<std::array<int, 3>> out;
  while (ring.size() > 3) {
    const std::size_t k = ring.size();
    const std::size_t i = std::size_t(std::max_element(shape.begin(), shape.end()) - shape.begin());
    if (!(shape[i] >= 0)) return {};
    out.push_back({ring[(i + k - 1) % k], ring[i], ring[(i + 1) % k]});
    ring.erase(ring.begin() + std::ptrdiff_t(i));
    shape.erase(shape.begin() + std::ptrdiff_t(i));
    const std::size_t before = (i + k - 2) % (k - 1), after = i % (k - 1);
    shape[before] = ear(before);
    shape[after] = ear(after);
  }
  if (!(orient(ring[0], ring[1], ring[2]) > 0)) return {};
  out.push_back({ring[0], ring[1], ring[2]});
  return out;
}

}  // namespace angiosynth
