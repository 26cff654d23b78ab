#include "mesh/vessel_surface.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "raster/capsule_rasterizer.hpp"
#include "raster/vessel_capsule.hpp"

namespace angiosynth {
namespace {

// A vertex of the mesh is the zero crossing on one grid edge: its tree, then the edge (the lower
// grid point's index × 8 + the edge's direction, 1 … 7 as the bits x, y, z of its step).
struct EdgeKey {
  std::int32_t tree;
  std::int64_t edge;
  auto operator<=>(const EdgeKey&) const = default;
};

struct EdgeVertex {
  EdgeKey key;
  Vec3 position;
};

struct KeyedTriangle {
  std::int32_t tree;
  std::int64_t edge[3];
};

struct BrickMesh {
  std::vector<EdgeVertex> vertices;  // may repeat: every tetrahedron on an edge lists its vertex
  std::vector<KeyedTriangle> triangles;
};

constexpr int kPoints = kBrick + 1;  // grid points per brick edge (the next brick's first layer too)

// A crossing never sits closer than this share of its edge to a grid point: triangles keep a
// positive area and vertices stay apart after single-precision formats round them (the surface
// moves by at most 1 % of a step).
constexpr double kEdgeMargin = 0.01;

// The six tetrahedra of a cube: corner paths 0 → 7 (corner bits x, y, z), one per axis order.
// Regula falsi steps for a vertex on its edge.
constexpr int kRootIterations = 12;

constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

// Signed distance to the union of the capsules (+∞ for none).
double unionDistance(const std::vector<Capsule>& caps, const Vec3& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& c : caps) best = std::min(best, c.depth(p));
  return best;
}

class BrickContourer {
 public:
  BrickContourer(const VolumeGrid& g, std::int32_t tree, const double* f, const std::vector<Capsule>& caps, const std::int64_t base[3],
                 BrickMesh& out)
      : g_(g), tree_(tree), f_(f), caps_(caps), out_(out) {
    for (int a = 0; a < 3; ++a) base_[a] = base[a];
  }

  void cube(int i, int j, int k) {
    double v[8];
    bool any_in = false, any_out = false;
    for (int c = 0; c < 8; ++c) {
      v[c] = f_[at(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
      (v[c] < 0 ? any_in : any_out) = true;
    }
    if (!(any_in && any_out)) return;
    for (const auto& tet : kTets) {
      int in[4], out[4], ni = 0, no = 0;
      for (int q = 0; q < 4; ++q) (v[tet[q]] < 0 ? in[ni++] : out[no++]) = tet[q];
      if (ni == 0 || no == 0) continue;
      Vec3 c_in(0, 0, 0), c_out(0, 0, 0);
      for (int q = 0; q < ni; ++q) c_in += corner(i, j, k, in[q]) / double(ni);
      for (int q = 0; q < no; ++q) c_out += corner(i, j, k, out[q]) / double(no);
      const Vec3 outward = c_out - c_in;
      if (ni == 1) {
        triangle(i, j, k, v, {in[0], out[0]}, {in[0], out[1]}, {in[0], out[2]}, outward);
      } else if (ni == 3) {
        triangle(i, j, k, v, {in[0], out[0]}, {in[1], out[0]}, {in[2], out[0]}, outward);
      } else {  // a quadrilateral, in its cyclic order, as two triangles
        triangle(i, j, k, v, {in[0], out[0]}, {in[0], out[1]}, {in[1], out[1]}, outward);
        triangle(i, j, k, v, {in[0], out[0]}, {in[1], out[1]}, {in[1], out[0]}, outward);
      }
    }
  }

 private:
  using Edge = std::array<int, 2>;  // two corners of the cube

  std::size_t at(int i, int j, int k) const { return std::size_t(i + kPoints * (j + kPoints * k)); }
  Vec3 corner(int i, int j, int k, int c) const {
    return g_.centre(base_[0] + i + (c & 1), base_[1] + j + ((c >> 1) & 1), base_[2] + k + ((c >> 2) & 1));
  }

  // The vertex on the edge between corners a (inside) and b (outside): its key and position.
  EdgeVertex crossing(int i, int j, int k, const double* v, Edge e) const {
    int lo = e[0], hi = e[1];
    if (lo > hi) std::swap(lo, hi);  // Freudenthal edges step up: corner bits of lo ⊂ those of hi
    const std::int64_t x = base_[0] + i + (lo & 1), y = base_[1] + j + ((lo >> 1) & 1), z = base_[2] + k + ((lo >> 2) & 1);
    const std::int64_t point = x + std::int64_t(g_.dims[0]) * (y + std::int64_t(g_.dims[1]) * z);
    const Vec3 pa = corner(i, j, k, e[0]), pb = corner(i, j, k, e[1]);
    const double t = std::clamp(zeroOnEdge(pa, pb, v[e[0]], v[e[1]]), kEdgeMargin, 1 - kEdgeMargin);
    return {{tree_, point * 8 + (hi ^ lo)}, pa + (pb - pa) * t};
  }

  // Where the distance crosses zero between a (inside, fa < 0) and b (fb > 0), as a share of
  // the edge: regula falsi with the Illinois step, so the vertex lies on the vessels' surface
  // and not where the linear interpolation puts it (off by up to half a step at the creases
  // where vessels meet). Every brick that holds the edge computes the same point: the same
  // values (all capsules within the band) in the same order.
  double zeroOnEdge(const Vec3& a, const Vec3& b, double fa, double fb) const {
    double lo = 0, hi = 1;
    int side = 0;
    for (int it = 0; it < kRootIterations; ++it) {
      const double t = (lo * fb - hi * fa) / (fb - fa);
      const double ft = unionDistance(caps_, a + (b - a) * t);
      if (ft < 0) {
        lo = t, fa = ft;
        if (side == -1) fb /= 2;
        side = -1;
      } else {
        hi = t, fb = ft;
        if (side == 1) fa /= 2;
        side = 1;
      }
      if (hi - lo < 1e-9) break;
    }
    return (lo * fb - hi * fa) / (fb - fa);
  }

  void triangle(int i, int j, int k, const double* v, Edge e0, Edge e1, Edge e2, const Vec3& outward) {
    EdgeVertex p[3] = {crossing(i, j, k, v, e0), crossing(i, j, k, v, e1), crossing(i, j, k, v, e2)};
    if (dot(cross(p[1].position - p[0].position, p[2].position - p[0].position), outward) < 0) std::swap(p[1], p[2]);
    out_.triangles.push_back({tree_, {p[0].key.edge, p[1].key.edge, p[2].key.edge}});
    for (const auto& q : p) out_.vertices.push_back(q);
  }

  const VolumeGrid& g_;
  std::int32_t tree_;
  const double* f_;
  const std::vector<Capsule>& caps_;
  std::int64_t base_[3];
  BrickMesh& out_;
};

// The signed distance at the brick's 9³ grid points for one tree's vessels (min over its
// capsules; a point exactly on the surface counts as outside, so every crossing lies inside an
// edge); points beyond the grid are outside.
void sampleDistance(const VolumeGrid& g, const std::int64_t base[3], const std::vector<Capsule>& caps, double* f) {
  for (int k = 0; k < kPoints; ++k)
    for (int j = 0; j < kPoints; ++j)
      for (int i = 0; i < kPoints; ++i) {
        const std::int64_t x = base[0] + i, y = base[1] + j, z = base[2] + k;
        const double best = g.contains(x, y, z) ? unionDistance(caps, g.centre(x, y, z)) : std::numeric_limits<double>::infinity();
        f[i + kPoints * (j + kPoints * k)] = best == 0 ? std::numeric_limits<double>::min() : best;
      }
}

// The connected surface of each vertex (through shared triangles), as one representative vertex.
std::vector<std::int32_t> componentOf(const SurfaceMesh& m) {
  std::vector<std::int32_t> parent(m.vertices.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = std::int32_t(i);
  const auto find = [&](std::int32_t v) {
    while (parent[std::size_t(v)] != v) v = parent[std::size_t(v)] = parent[std::size_t(parent[std::size_t(v)])];
    return v;
  };
  for (const auto& t : m.triangles) {
    const auto a = find(t[0]);
    parent[std::size_t(find(t[1]))] = a;
    parent[std::size_t(find(t[2]))] = a;
  }
  for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = find(std::int32_t(v));
  return parent;
}

// Drops the closed components that enclose a negative volume: pockets of outside space the grid
// cannot resolve (a wedge between two vessels closed off between grid points), which the union
// of a tree's vessels does not have. Returns how many.
std::int64_t removeCavities(SurfaceMesh& m) {
  const auto component = componentOf(m);
  std::vector<double> volume(m.vertices.size(), 0.0);  // per component representative: 6 × its signed volume
  for (const auto& t : m.triangles) volume[std::size_t(component[std::size_t(t[0])])] += dot(m.vertices[t[0]], cross(m.vertices[t[1]], m.vertices[t[2]]));
  std::int64_t removed = 0;
  for (std::size_t v = 0; v < volume.size(); ++v) removed += component[v] == std::int32_t(v) && volume[v] < 0;
  if (removed == 0) return 0;
  // Kept vertices keep their order.
  std::vector<std::int32_t> renumber(m.vertices.size(), -1);
  std::vector<Vec3> vertices;
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::vector<std::int32_t> trees;
  for (std::size_t v = 0; v < renumber.size(); ++v)
    if (!(volume[std::size_t(component[v])] < 0)) renumber[v] = std::int32_t(vertices.size()), vertices.push_back(m.vertices[v]);
  for (std::size_t k = 0; k < m.triangles.size(); ++k)
    if (renumber[std::size_t(m.triangles[k][0])] >= 0) triangles.push_back(m.triangles[k]), trees.push_back(m.triangle_tree[k]);
  for (auto& t : triangles)
    for (auto& v : t) v = renumber[std::size_t(v)];
  m.vertices = std::move(vertices);
  m.triangles = std::move(triangles);
  m.triangle_tree = std::move(trees);
  return removed;
}

}  // namespace

SurfaceMesh vesselSurface(const VascularTree& t, const SurfaceOptions& o, SurfaceReport* report,
                          const std::function<void(std::int64_t, std::int64_t)>& progress) {
  SurfaceMesh mesh;
  Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  double r_min = INFINITY, area = 0;
  for (std::int32_t s = 0; s < t.nodeCount(); ++s) {
    if (t.isRoot(s) || t.isLink(s)) continue;  // a link lies inside the cap of the vessel ending at its junction
    const double r = t.maxRadius(s);
    r_min = std::min({r_min, t.radius[s], t.startRadius(s)});
    for (const Vec3& p : {t.position[t.parent[s]], t.position[s]}) {
      lo = componentMin(lo, p - Vec3(r, r, r));
      hi = componentMax(hi, p + Vec3(r, r, r));
    }
    area += 2 * std::numbers::pi * r * t.length[s] + 4 * std::numbers::pi * r * r;
  }
  if (!(r_min < INFINITY)) return mesh;
  if (!(r_min > 0)) throw InputError("", 0, "a vessel of radius 0 has no surface; every radius must be > 0");
  const double h = o.voxel_mm > 0 ? o.voxel_mm : 2 * r_min / std::max(1, o.samples_across);
  // Bricks hold every vessel whose surface lies within `band` of their grid points: a crossing
  // edge (≤ √3 h long) has both ends that close, so neighbouring bricks agree on their values.
  const double band = 3 * h;
  VolumeGrid g;
  g.spacing_mm = Vec3(h, h, h);
  g.origin_mm = lo - Vec3(band, band, band);
  for (int a = 0; a < 3; ++a) {
    const double n = std::ceil((hi[a] - lo[a] + 2 * band) / h) + 1;
    if (!(n < double(1 << 20)))
      throw InputError("", 0, "a surface step of " + std::to_string(h) + " mm needs " + std::to_string(n) +
                                  " grid points along an axis; allowed: at most 2^20 (choose a larger voxel)");
    g.dims[a] = std::int32_t(n);
  }
  VascularTree inflated = t;
  for (std::int32_t s = 0; s < t.nodeCount(); ++s) {
    inflated.radius[s] += band;
    if (inflated.radius_start[s] >= 0) inflated.radius_start[s] += band;
  }
  // Bins (12 bytes a pair), then about 8 triangles per h² of vessel surface (marching
  // tetrahedra; measured 7.7), at a peak of about 170 bytes each (measured 166): the keyed
  // triangles, the vertices of every brick until they are welded, and the mesh.
  const double estimate = brickPairBound(inflated, g) * 12 + area / (h * h) * 8 * 170;
  if (report) report->voxel_mm = h, report->estimated_bytes = estimate;
  if (o.memory_limit > 0 && estimate > double(o.memory_limit))
    throw InputError("", 0, "the surface at a step of " + std::to_string(h) + " mm needs about " + formatBytes(std::uint64_t(estimate)) +
                                " of memory, more than the limit of " + formatBytes(o.memory_limit) +
                                "; allowed: a larger voxel or a higher --memory-limit");
  const BrickBins bins = binSegments(inflated, g);
  if (report) report->bricks = std::int64_t(bins.brick_ids.size());
  const std::int64_t nb = std::int64_t(bins.brick_ids.size());
  std::vector<BrickMesh> bricks(bins.brick_ids.size());
  // In batches, so progress is reported from this thread.
  const std::int64_t batch = 4096;
  for (std::int64_t first = 0; first < nb; first += batch) {
    const std::int64_t last = std::min(nb, first + batch);
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(first, last, 8), [&](const tbb::blocked_range<std::int64_t>& r) {
      std::vector<double> f(std::size_t(kPoints * kPoints * kPoints));
      std::vector<Capsule> caps;
      for (std::int64_t b = r.begin(); b != r.end(); ++b) {
        const std::int64_t id = bins.brick_ids[std::size_t(b)];
        const std::int64_t base[3] = {kBrick * (id % bins.bricks[0]), kBrick * ((id / bins.bricks[0]) % bins.bricks[1]),
                                      kBrick * (id / (std::int64_t(bins.bricks[0]) * bins.bricks[1]))};
        const auto& segs = bins.segments[std::size_t(b)];
        std::vector<std::int32_t> trees;
        for (auto s : segs)
          if (!t.isLink(s)) trees.push_back(t.tree.empty() ? 0 : t.tree[s]);
        std::sort(trees.begin(), trees.end());
        trees.erase(std::unique(trees.begin(), trees.end()), trees.end());
        for (auto tree : trees) {
          caps.clear();
          for (auto s : segs)
            if (!t.isLink(s) && (t.tree.empty() ? 0 : t.tree[s]) == tree) caps.push_back(capsuleOf(t, s));
          sampleDistance(g, base, caps, f.data());
          BrickContourer contour(g, tree, f.data(), caps, base, bricks[std::size_t(b)]);
          for (int k = 0; k < kBrick; ++k)
            for (int j = 0; j < kBrick; ++j)
              for (int i = 0; i < kBrick; ++i) contour.cube(i, j, k);
        }
        // Each tetrahedron listed its three vertices: keep one per edge (a fifth of them).
        auto& v = bricks[std::size_t(b)].vertices;
        std::sort(v.begin(), v.end(), [](const EdgeVertex& x, const EdgeVertex& y) { return x.key < y.key; });
        v.erase(std::unique(v.begin(), v.end(), [](const EdgeVertex& x, const EdgeVertex& y) { return x.key == y.key; }), v.end());
        v.shrink_to_fit();
      }
    });
    if (progress) progress(last, nb);
  }
  // Weld: one vertex per (tree, edge), numbered in key order; triangles in brick order.
  std::vector<EdgeVertex> all;
  std::size_t triangles = 0;
  for (auto& b : bricks) {
    all.insert(all.end(), b.vertices.begin(), b.vertices.end());
    triangles += b.triangles.size();
    std::vector<EdgeVertex>().swap(b.vertices);
  }
  std::sort(all.begin(), all.end(), [](const EdgeVertex& a, const EdgeVertex& b) { return a.key < b.key; });
  all.erase(std::unique(all.begin(), all.end(), [](const EdgeVertex& a, const EdgeVertex& b) { return a.key == b.key; }), all.end());
  mesh.vertices.reserve(all.size());
  for (const auto& v : all) mesh.vertices.push_back(v.position);
  mesh.triangles.reserve(triangles);
  mesh.triangle_tree.reserve(triangles);
  const auto index = [&](std::int32_t tree, std::int64_t edge) {
    const EdgeKey key{tree, edge};
    const auto it = std::lower_bound(all.begin(), all.end(), key, [](const EdgeVertex& v, const EdgeKey& k) { return v.key < k; });
    return std::int32_t(it - all.begin());
  };
  for (const auto& b : bricks)
    for (const auto& tri : b.triangles) {
      mesh.triangles.push_back({index(tri.tree, tri.edge[0]), index(tri.tree, tri.edge[1]), index(tri.tree, tri.edge[2])});
      mesh.triangle_tree.push_back(tri.tree);
    }
  const auto removed = removeCavities(mesh);
  if (report) report->cavities_removed = removed;
  return mesh;
}

MeshTopology meshTopology(const SurfaceMesh& m) {
  MeshTopology out;
  // Directed edges (from, to) sorted by their undirected pair: a closed, consistently oriented
  // surface uses every edge once in each direction.
  struct Use {
    std::int64_t a, b;
    bool forward;
  };
  std::vector<Use> edges;
  edges.reserve(3 * m.triangles.size());
  double six_v = 0;
  for (const auto& tri : m.triangles) {
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) ++out.degenerate_triangles;
    for (int e = 0; e < 3; ++e) {
      const std::int64_t a = tri[e], b = tri[(e + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), a < b});
    }
    six_v += dot(m.vertices[tri[0]], cross(m.vertices[tri[1]], m.vertices[tri[2]]));
  }
  out.volume_mm3 = six_v / 6;
  std::sort(edges.begin(), edges.end(), [](const Use& x, const Use& y) { return std::tie(x.a, x.b, x.forward) < std::tie(y.a, y.b, y.forward); });
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    if (j - i == 1) ++out.boundary_edges;
    else if (j - i > 2) ++out.nonmanifold_edges;
    else if (edges[i].forward == edges[i + 1].forward) ++out.misoriented_edges;
    i = j;
  }
  // Components (union-find over shared vertices) and V − E + F, per tree.
  std::int32_t trees = 0;
  for (auto tree : m.triangle_tree) trees = std::max(trees, tree + 1);
  out.tree_components.assign(std::size_t(trees), 0);
  out.tree_euler.assign(std::size_t(trees), 0);
  const auto component = componentOf(m);
  std::vector<std::int32_t> tree_of(m.vertices.size(), -1);
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    out.tree_euler[std::size_t(m.triangle_tree[k])] += 1;  // F
    for (auto v : m.triangles[k]) tree_of[std::size_t(v)] = m.triangle_tree[k];
  }
  for (std::size_t v = 0; v < component.size(); ++v) {
    if (tree_of[v] < 0) continue;
    out.tree_euler[std::size_t(tree_of[v])] += 1;  // V
    out.tree_components[std::size_t(tree_of[v])] += component[v] == std::int32_t(v);
  }
  for (std::size_t i = 0; i < edges.size(); i += 2) out.tree_euler[std::size_t(tree_of[std::size_t(edges[i].a)])] -= 1;  // E (closed: two uses each)
  return out;
}

}  // namespace angiosynth
