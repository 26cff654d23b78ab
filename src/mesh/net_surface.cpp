#include "mesh/net_surface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <vector>

#include "mesh/dual_geometry.hpp"
#include "mesh/surface_checks.hpp"
#include "mesh/union_distance.hpp"

namespace angiosynth {
namespace {

// Cell corners are numbered by their offsets: bit a set is +1 along axis a. Edge e runs along
// axis e / 4 from the corner whose other two bits are those of e % 4 (axis a + 1 in bit 0, a + 2 in bit 1).
int edgeId(int axis, int low_corner) { return 4 * axis + ((low_corner >> ((axis + 1) % 3)) & 1) + 2 * ((low_corner >> ((axis + 2) % 3)) & 1); }
int edgeLow(int e) {
  const int a = e / 4, r = e % 4;
  return ((r & 1) << ((a + 1) % 3)) | (((r >> 1) & 1) << ((a + 2) % 3));
}

// A face's corners in cyclic order (axes a + 1, a + 2 as x, y: 00, 10, 11, 01), and its edges
// from corner k to k + 1.
struct Face {
  int corner[4];
  int edge[4];
};
std::array<Face, 6> makeFaces() {
  std::array<Face, 6> faces{};
  for (int a = 0; a < 3; ++a)
    for (int s = 0; s < 2; ++s) {
      Face& f = faces[std::size_t(2 * a + s)];
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int k = 0; k < 4; ++k) f.corner[k] = (s << a) | (uv[k][0] << b) | (uv[k][1] << c);
      for (int k = 0; k < 4; ++k) {
        const int p = f.corner[k], q = f.corner[(k + 1) % 4], axis = (p ^ q) == (1 << b) ? b : c;
        f.edge[k] = edgeId(axis, std::min(p, q));
      }
    }
  return faces;
}
const std::array<Face, 6> kFaces = makeFaces();

struct UnionFind12 {
  int parent[12];
  UnionFind12() { std::iota(parent, parent + 12, 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(int x, int y) { parent[find(x)] = find(y); }
};

// A cell the surface passes through: its first vertex, and each crossed edge's sheet.
struct NetCell {
  std::int32_t first_vertex;
  std::int8_t sheet[12];
};

}  // namespace

namespace {

// The signed distance at the lattice points near the solids (within two steps of their boxes:
// every corner of a cell the surface passes through); further out the points are outside, far.
struct NetGrid {
  Vec3 origin;
  double h = 0;
  std::int64_t n[3] = {0, 0, 0};
  std::vector<double> f;
  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const { return x + n[0] * (y + n[1] * z); }
  Vec3 point(std::int64_t x, std::int64_t y, std::int64_t z) const { return origin + Vec3(double(x), double(y), double(z)) * h; }
};

void sampleDistance(NetGrid& g, const std::vector<Solid>& solids) {
  const double h = g.h;
  const auto& n = g.n;
  const Vec3& origin = g.origin;
  const auto index = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return g.index(x, y, z); };
  const auto point = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return g.point(x, y, z); };
  const auto distance = [&](const Vec3& p) { return unionDistance(solids, p); };
  auto& f = g.f;
  constexpr double kFar = 1e30;
  f.assign(std::size_t(n[0] * n[1] * n[2]), kFar);
  std::vector<char> near(f.size(), 0);
  for (const auto& sol : solids) {
    std::int64_t b0[3], b1[3];
    const double reach = sol.bound + kFillet * h + 2 * h;
    for (int a = 0; a < 3; ++a) {
      b0[a] = std::max<std::int64_t>(0, std::int64_t(std::floor((sol.centre[a] - reach - origin[a]) / h)));
      b1[a] = std::min<std::int64_t>(n[a] - 1, std::int64_t(std::ceil((sol.centre[a] + reach - origin[a]) / h)));
    }
    const Capsule& cap = sol.c;
    for (std::int64_t z = b0[2]; z <= b1[2]; ++z)
      for (std::int64_t y = b0[1]; y <= b1[1]; ++y)
        for (std::int64_t x = b0[0]; x <= b1[0]; ++x)
          if (cap.depth(point(x, y, z)) < kFillet * h + 2 * h) near[std::size_t(index(x, y, z))] = 1;
  }
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!near[i]) continue;
    const auto x = std::int64_t(i) % n[0], y = (std::int64_t(i) / n[0]) % n[1], z = std::int64_t(i) / (n[0] * n[1]);
    double v = distance(point(x, y, z));
    if (v == 0) v = std::numeric_limits<double>::min();  // on the surface counts as outside
    f[i] = v;
  }
}

// The sheets of each crossed cell, one vertex each (the mean of its crossings taken onto the
// surface), into `mesh`; `cell_of` numbers the crossed cells.
std::vector<NetCell> netCells(const NetGrid& g, const std::vector<Solid>& solids, SurfaceMesh& mesh, std::vector<std::int32_t>& cell_of) {
  const double h = g.h;
  const auto& n = g.n;
  const auto& f = g.f;
  const auto index = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return g.index(x, y, z); };
  const auto point = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return g.point(x, y, z); };
  const auto distance = [&](const Vec3& p) { return unionDistance(solids, p); };
  const std::int64_t cx = n[0] - 1, cy = n[1] - 1, cz = n[2] - 1;
  cell_of.assign(std::size_t(cx * cy * cz), -1);
  std::vector<NetCell> cells;
  const double margin = 1e-3 * h;
  for (std::int64_t z = 0; z < cz; ++z)
    for (std::int64_t y = 0; y < cy; ++y)
      for (std::int64_t x = 0; x < cx; ++x) {
        double v[8];
        int inside = 0;
        for (int c = 0; c < 8; ++c) {
          v[c] = f[std::size_t(index(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1)))];
          inside |= int(v[c] < 0) << c;
        }
        if (inside == 0 || inside == 255) continue;
        const auto crossed = [&](int e) {
          const int p = edgeLow(e), q = p | (1 << (e / 4));
          return ((inside >> p) & 1) != ((inside >> q) & 1);
        };
        UnionFind12 sheets;
        for (const auto& face : kFaces) {
          int ce[4], nc = 0;
          for (int k = 0; k < 4; ++k)
            if (crossed(face.edge[k])) ce[nc++] = k;
          if (nc == 2) {
            sheets.join(face.edge[ce[0]], face.edge[ce[1]]);
          } else if (nc == 4) {
            // Corners 0 and 2 share a sign: joined across the face where the bilinear saddle has it.
            const double a = v[face.corner[0]], b = v[face.corner[1]], c = v[face.corner[2]], d = v[face.corner[3]];
            const double den = a + c - b - d, saddle = den != 0 ? (a * c - b * d) / den : -1.0;
            if ((saddle < 0) == (a < 0)) {  // 0 and 2 joined: corners 1 and 3 cut off
              sheets.join(face.edge[0], face.edge[1]), sheets.join(face.edge[2], face.edge[3]);
            } else {
              sheets.join(face.edge[3], face.edge[0]), sheets.join(face.edge[1], face.edge[2]);
            }
          }
        }
        NetCell cell;
        cell.first_vertex = std::int32_t(mesh.vertices.size());
        int root_sheet[12];
        std::fill(root_sheet, root_sheet + 12, -1);
        Vec3 sum[4];
        int count[4] = {0, 0, 0, 0}, sheets_n = 0;
        const Vec3 corner0 = point(x, y, z);
        for (int e = 0; e < 12; ++e) {
          cell.sheet[e] = -1;
          if (!crossed(e)) continue;
          const int r = sheets.find(e);
          if (root_sheet[r] < 0) root_sheet[r] = sheets_n, sum[sheets_n] = Vec3(0, 0, 0), ++sheets_n;
          const int k = root_sheet[r];
          cell.sheet[e] = std::int8_t(k);
          const int p = edgeLow(e), q = p | (1 << (e / 4));
          const double tt = v[p] / (v[p] - v[q]);
          const Vec3 cp(double(p & 1), double((p >> 1) & 1), double((p >> 2) & 1)), cq(double(q & 1), double((q >> 1) & 1), double((q >> 2) & 1));
          sum[k] += corner0 + (cp + (cq - cp) * tt) * h;
          ++count[k];
        }
        for (int k = 0; k < sheets_n; ++k) {
          // The sheet's crossings' mean, taken onto the surface by Newton steps, kept in the cell.
          const Vec3 lo_c = corner0 + Vec3(margin, margin, margin), hi_c = corner0 + Vec3(h - margin, h - margin, h - margin);
          const Vec3 p = ontoSurface(sum[k] / double(count[k]), distance, 1e-3 * h, 1e-6 * h,
                                     [&](const Vec3& q) { return componentMin(componentMax(q, lo_c), hi_c); });
          mesh.vertices.push_back(p);
          mesh.vertex_step.push_back(float(h));
        }
        cell_of[std::size_t(x + cx * (y + cy * z))] = std::int32_t(cells.size());
        cells.push_back(cell);
      }
  return cells;
}

// A quadrilateral around each crossed edge, from the four cells around it (counter-clockwise
// seen from the outside).
void connectQuads(const NetGrid& g, const std::vector<NetCell>& cells, const std::vector<std::int32_t>& cell_of, SurfaceMesh& mesh) {
  const auto& n = g.n;
  const auto& f = g.f;
  const auto index = [&](std::int64_t x, std::int64_t y, std::int64_t z) { return g.index(x, y, z); };
  const std::int64_t cx = n[0] - 1, cy = n[1] - 1, cz = n[2] - 1;
  for (std::int64_t z = 1; z < cz; ++z)
    for (std::int64_t y = 1; y < cy; ++y)
      for (std::int64_t x = 1; x < cx; ++x) {
        const std::int64_t pt[3] = {x, y, z};
        const bool in0 = f[std::size_t(index(x, y, z))] < 0;
        for (int a = 0; a < 3; ++a) {
          std::int64_t q[3] = {x, y, z};
          ++q[a];
          if ((f[std::size_t(index(q[0], q[1], q[2]))] < 0) == in0) continue;
          const int b = (a + 1) % 3, c = (a + 2) % 3;
          const int off[4][2] = {{-1, -1}, {0, -1}, {0, 0}, {-1, 0}};
          std::int32_t quad[4];
          for (int k = 0; k < 4; ++k) {
            std::int64_t cc[3] = {pt[0], pt[1], pt[2]};
            cc[b] += off[k][0], cc[c] += off[k][1];
            const auto id = cell_of[std::size_t(cc[0] + cx * (cc[1] + cy * cc[2]))];
            // The edge in that cell: along a, from the corner at −off.
            const int low = ((-off[k][0]) << b) | ((-off[k][1]) << c);
            const auto& cell = cells[std::size_t(id)];
            quad[k] = cell.first_vertex + cell.sheet[edgeId(a, low)];
          }
          if (!in0) std::swap(quad[1], quad[3]);  // outward is −a
          appendQuad(mesh, quad);
        }
      }
}

}  // namespace

std::optional<SurfaceMesh> netSurface(const VascularTree& t, const SurfaceOptions& o, SurfaceReport* report, NetReport* net) {
  const auto refuse = [&](const char* why) -> std::optional<SurfaceMesh> {
    if (net) net->refused = why;
    return std::nullopt;
  };
  if (net) *net = NetReport();
  for (auto c : o.vessel_max_cell_mm)
    if (c > 0) return refuse("gaps to resolve");
  std::vector<std::int32_t> vessels;
  double r_min = INFINITY, r_max = 0;
  for (std::int32_t s = 0; s < t.nodeCount(); ++s) {
    if (t.isRoot(s) || t.isLink(s)) continue;
    if (!t.tree.empty() && t.tree[s] != t.tree[vessels.empty() ? s : vessels.front()]) return refuse("several trees");
    vessels.push_back(s);
    r_min = std::min({r_min, t.radius[s], t.startRadius(s)});
    r_max = std::max(r_max, t.maxRadius(s));
  }
  if (vessels.empty()) return SurfaceMesh();
  if (vessels.size() > kNetMaxVessels) return refuse("too many vessels");
  if (!(r_min > 0)) return refuse("a vessel of radius 0");
  // vesselSurface's finest step and the fillet of its cells there.
  const int across = std::max(1, o.samples_across);
  double h = o.voxel_mm > 0 ? o.voxel_mm : 2 * r_min / across;
  if (o.max_cell_mm > 0 && !(o.voxel_mm > 0)) h = std::min(h, o.max_cell_mm);
  // One step for all: thick vessels get more triangles than marching tetrahedra give them at
  // their own coarser level; nets only where that costs less in all (per area: kNetTriangles per
  // step², marching tetrahedra kTetTriangles per step² of each vessel's level).
  double net_cost = 0, tet_cost = 0;
  for (auto s : vessels) {
    const double r = std::min(t.radius[s], t.startRadius(s)), area = 2 * std::numbers::pi * t.maxRadius(s) * (t.length[s] + 2 * r);
    double c = 2 * r / across;
    if (o.max_cell_mm > 0) c = std::min(c, o.max_cell_mm);
    const int level = c >= 2 * h ? int(std::floor(std::log2(c / h) + 1e-9)) : 0;
    net_cost += kNetTriangles * area;
    tet_cost += kTetTriangles * area / double(std::int64_t(1) << (2 * std::min(level, 20)));
  }
  if (net_cost > tet_cost) {
    if (net) net->costlier = true;
    return refuse("marching tetrahedra make fewer triangles");
  }
  std::vector<Solid> solids;
  Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  for (auto s : vessels) {
    solids.emplace_back(capsuleOf(t, s), kFillet * h);
    const double r = t.maxRadius(s);
    for (const Vec3& p : {t.position[t.parent[s]], t.position[s]}) lo = componentMin(lo, p - Vec3(r, r, r)), hi = componentMax(hi, p + Vec3(r, r, r));
  }
  // Two steps of room (and the fillet's stand-off) keep the surface off the grid's border.
  const double room = 2 * h + kFillet * h;
  const Vec3 origin = lo - Vec3(room, room, room);
  std::int64_t n[3];
  for (int a = 0; a < 3; ++a) n[a] = std::int64_t(std::ceil((hi[a] - lo[a] + 2 * room) / h)) + 1;
  if (n[0] * n[1] * n[2] > kNetMaxPoints) return refuse("grid too large");
  const auto distance = [&](const Vec3& p) { return unionDistance(solids, p); };
  NetGrid g;
  g.origin = origin;
  g.h = h;
  std::copy(n, n + 3, g.n);
  sampleDistance(g, solids);
  const auto& f = g.f;
  if (report) report->voxel_mm = h, report->coarsest_mm = h, report->levels = 1, report->estimated_bytes = double(f.size()) * 12;

  SurfaceMesh mesh;
  std::vector<std::int32_t> cell_of;
  const std::vector<NetCell> cells = netCells(g, solids, mesh, cell_of);

  connectQuads(g, cells, cell_of, mesh);
  mesh.triangle_tree.assign(mesh.triangles.size(), t.tree.empty() ? 0 : t.tree[vessels.front()]);
  if (report) report->cells = std::int64_t(cells.size()), report->units = 1;

  // The flat triangles lie inside the convex wall (chords): each vertex moves out along its
  // normal by ¾ of its triangles' area-weighted gap at their centroids.
  if (o.restore_volume) {
    const double moved = restoreVolumeAlongNormals(mesh, [&](std::int32_t, const Vec3& p) { return distance(p); });
    if (report) report->largest_volume_move_mm = moved;
  }
  if (!closedManifold(mesh)) return refuse("not a closed manifold");
  if (!freeOfCrossings(mesh, origin, h)) return refuse("self-intersecting");
  if (o.finish) {
    o.finish(mesh, [&](std::int32_t, const Vec3& p) { return strictDistance(solids, p); });
  }
  return mesh;
}

}  // namespace angiosynth
