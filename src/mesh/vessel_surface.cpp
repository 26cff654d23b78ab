#include "mesh/vessel_surface.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "mesh/balanced_octree.hpp"
#include "mesh/dual_geometry.hpp"
#include "mesh/surface_checks.hpp"
#include "mesh/union_distance.hpp"
#include "raster/capsule_rasterizer.hpp"
#include "raster/vessel_capsule.hpp"

namespace angiosynth {
namespace {

// A vertex of the mesh is the zero crossing on one edge of the tetrahedra: its tree, then the
// edge, named by its midpoint (in quarter steps, packed; in a conforming mesh no two edges share one).
struct EdgeKey {
  std::int32_t tree;
  std::int64_t edge;
  auto operator<=>(const EdgeKey&) const = default;
};

struct EdgeVertex {
  EdgeKey key;
  Vec3 position;
  Vec3 along;  // mm: its edge, from the inside end to the outside end
  double t;    // where on the edge it lies
};

struct KeyedTriangle {
  std::int64_t edge[3];
};

// A unit's dual contour: its leaves' sheet vertices, and for each grid edge of a leaf's boundary
// the surface crosses, the leaf's sheet there and the leaf's direction around the edge.
struct DualRecord {
  std::int32_t tree;
  std::int64_t edge;    // the edge's midpoint in quarter steps, packed
  double angle;         // of the leaf's centre around the edge (counter-clockwise about its axis)
  std::int32_t vertex;  // in the unit
  bool low_inside;      // the edge's lower end lies inside
};
// Where one leaf's sheet crosses one of its faces in two or more separate arcs, each arc: the two
// grid edges it ends on (keys, lo < hi) and a point of it on the surface. If the leaf across the
// face has them in one sheet too, one vertex per sheet would give that pair of vertices one edge
// for both arcs (used by four triangles); a vertex on each arc keeps the surface a manifold.
struct ArcRecord {
  std::int32_t tree;
  std::int64_t lo, hi;
  std::int64_t plane;  // the face's: axis + 3 × its coordinate in half steps
  Vec3 position;       // mm
  float step;          // mm: the leaf's size
};
struct DualUnit {
  std::vector<Vec3> vertices;
  std::vector<float> steps;  // mm: the leaf's size
  std::vector<DualRecord> records;
  std::vector<ArcRecord> arcs;
};

struct UnitMesh {
  std::vector<EdgeVertex> vertices;                    // one per (tree, edge) the unit's tetrahedra cross, in key order
  std::vector<std::array<std::int32_t, 3>> triangles;  // into vertices
  std::vector<std::int32_t> triangle_tree;
};

// A crossing never sits closer than this share of its edge to a grid point: triangles keep a
// positive area and vertices stay apart after single-precision formats round them (the surface
// moves by at most 1 % of a step).
constexpr double kEdgeMargin = 0.01;

// Regula falsi steps for a vertex on its edge.
constexpr int kRootIterations = 12;

// Leaves are meshed in units: the level-3 cell (8³ finest cells) holding them, or a coarser leaf
// on its own; a unit samples the distance once per lattice point it uses.
constexpr int kUnitLevel = 3;

// The lattice the octree lives on (level-0 cells one step wide; points in half steps) and the
// segments binned on its 8³ bricks. The distance at a point is the minimum over the capsules of
// the one bin that holds it, so every unit that samples a point gets the same value; bins hold
// every capsule within a band of the bin, so the value is exact inside vessels and near their
// surface and positive wherever the union's distance is.
struct Lattice {
  Vec3 origin;      // mm, lattice point 0
  double h = 0;     // mm, one step
  VolumeGrid grid;  // bins: voxel centres at the lattice's whole steps
  BrickBins bins;

  Vec3 position(const HalfPoint& q) const { return origin + Vec3(double(q[0]), double(q[1]), double(q[2])) * (0.5 * h); }
  // The bin of a coordinate in half steps: voxel x covers [x − ½, x + ½) steps, brick b voxels 8b … 8b + 7.
  static std::int64_t binOf(double half) { return std::int64_t(std::floor((half + 1) / (2 * kBrick))); }
  // The segments binned in brick (x, y, z); nullptr for none or a brick outside the grid.
  const std::vector<std::int32_t>* segmentsIn(std::int64_t x, std::int64_t y, std::int64_t z) const {
    if (x < 0 || y < 0 || z < 0 || x >= bins.bricks[0] || y >= bins.bricks[1] || z >= bins.bricks[2]) return nullptr;
    const std::int64_t id = x + std::int64_t(bins.bricks[0]) * (y + std::int64_t(bins.bricks[1]) * z);
    const auto it = std::lower_bound(bins.brick_ids.begin(), bins.brick_ids.end(), id);
    return it != bins.brick_ids.end() && *it == id ? &bins.segments[std::size_t(it - bins.brick_ids.begin())] : nullptr;
  }
};

class UnitMesher {
 public:
  UnitMesher(const VascularTree& t, const Lattice& lat, LeafSplitter& splitter, const std::vector<double>& fillet)
      : t_(t), lat_(lat), splitter_(splitter), fillet_(fillet) {}

  void mesh(int level, const std::array<std::int64_t, 3>& cell, const OctreeLeaf* first, const OctreeLeaf* last, UnitMesh& out) {
    tets_.clear();
    scratch_.clear();
    for (auto* l = first; l != last; ++l) splitter_.tetrahedra(*l, scratch_);
    const auto trees = prepare(level, cell, first, last);
    for (const auto& tet : scratch_) {
      std::array<std::int32_t, 4> local;
      for (int q = 0; q < 4; ++q) local[std::size_t(q)] = localIndex(tet[std::size_t(q)]);
      tets_.push_back(local);
    }
    // Trees in order, each's vertices in edge order: the unit's vertices are in key order.
    for (auto tree : trees) meshTree(tree, out);
  }

  // The unit's dual contour (surface nets on the octree): per leaf, the sheets of the surface
  // through it and, for each grid edge of its boundary the surface crosses, the sheet there.
  void dual(int level, const std::array<std::int64_t, 3>& cell, const OctreeLeaf* first, const OctreeLeaf* last, DualUnit& out) {
    const auto trees = prepare(level, cell, first, last);
    for (auto tree : trees) {
      loadTree(tree);
      for (auto* l = first; l != last; ++l) dualLeaf(*l, tree, out);
    }
  }

 private:
  // The unit's lattice and bins; the trees with vessels there, in order.
  std::vector<std::int32_t> prepare(int level, const std::array<std::int64_t, 3>& cell, const OctreeLeaf* first, const OctreeLeaf* last) {
    // The unit's lattice: its points are those of its finest leaves' faces (balance: at most one
    // level finer), so steps of 2^(finest − 1) half steps (1 at level 0).
    int finest = level;
    for (auto* l = first; l != last; ++l) finest = std::min(finest, l->level);
    shift_ = std::max(0, finest - 1);
    const std::int64_t span = std::int64_t(2) << level;
    n_ = (span >> shift_) + 1;
    for (int a = 0; a < 3; ++a) base_[std::size_t(a)] = cell[std::size_t(a)] * span;
    // The bins the unit's points fall in, and the trees with vessels there.
    for (int a = 0; a < 3; ++a) {
      bin_lo_[std::size_t(a)] = Lattice::binOf(double(base_[std::size_t(a)]));
      bin_n_[std::size_t(a)] = Lattice::binOf(double(base_[std::size_t(a)] + span)) - bin_lo_[std::size_t(a)] + 1;
    }
    unit_bins_.clear();
    std::vector<std::int32_t> trees;
    for (std::int64_t k = 0; k < bin_n_[2]; ++k)
      for (std::int64_t j = 0; j < bin_n_[1]; ++j)
        for (std::int64_t i = 0; i < bin_n_[0]; ++i) {
          const auto* segs = lat_.segmentsIn(bin_lo_[0] + i, bin_lo_[1] + j, bin_lo_[2] + k);
          unit_bins_.push_back(segs);
          if (segs)
            for (auto s : *segs) trees.push_back(treeOf(s));
        }
    std::sort(trees.begin(), trees.end());
    trees.erase(std::unique(trees.begin(), trees.end()), trees.end());
    return trees;
  }

  std::int32_t treeOf(std::int32_t s) const { return t_.tree.empty() ? 0 : t_.tree[s]; }

  std::int32_t localIndex(const HalfPoint& q) const {
    std::int64_t idx = 0;
    for (int a = 2; a >= 0; --a) {
      const std::int64_t d = q[std::size_t(a)] - base_[std::size_t(a)];
      if (d < 0 || (d & ((std::int64_t(1) << shift_) - 1)) != 0 || (d >> shift_) >= n_)
        throw std::logic_error("surface mesher: a tetrahedron's corner is off its unit's lattice");
      idx = idx * n_ + (d >> shift_);
    }
    return std::int32_t(idx);
  }
  HalfPoint halfPoint(std::int32_t idx) const {
    return {base_[0] + ((idx % n_) << shift_), base_[1] + (((idx / n_) % n_) << shift_), base_[2] + ((idx / (n_ * n_)) << shift_)};
  }
  // The distance at a point given in half steps: the minimum over the capsules of its bin.
  double distance(const Vec3& q) const {
    std::int64_t b = 0;
    for (int a = 2; a >= 0; --a) b = b * bin_n_[std::size_t(a)] + (Lattice::binOf(q[a]) - bin_lo_[std::size_t(a)]);
    return unionDistance(caps_[std::size_t(b)], lat_.origin + q * (0.5 * lat_.h));
  }
  double value(std::int32_t idx) {
    if (stamp_[std::size_t(idx)] == generation_) return f_[std::size_t(idx)];
    double v = distance(asVec(halfPoint(idx)));
    if (v == 0) v = std::numeric_limits<double>::min();  // on the surface counts as outside: crossings lie inside edges
    stamp_[std::size_t(idx)] = generation_;
    return f_[std::size_t(idx)] = v;
  }

  // Where the distance crosses zero between a (inside, fa < 0) and b (fb > 0, maybe +∞: no
  // vessel listed there), as a share of the edge: regula falsi with the Illinois step, so the
  // vertex lies on the vessels' surface and not where the linear interpolation puts it (off by
  // up to half a step at the creases where vessels meet). Every unit that holds the edge
  // computes the same point: the same values at the same points, from the points' own bins.
  double zeroOnEdge(const Vec3& a, const Vec3& b, double fa, double fb) const {
    double lo = 0, hi = 1;
    int side = 0;
    const auto next = [&] { return std::isfinite(fb) ? (lo * fb - hi * fa) / (fb - fa) : 0.5 * (lo + hi); };
    const double close = 1e-5 * norm(b - a) * (0.5 * lat_.h);  // mm: below the single precision of STL at 10 cm
    for (int it = 0; it < kRootIterations; ++it) {
      const double t = next();
      const double ft = distance(a + (b - a) * t);
      if (std::abs(ft) < close) return t;
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
    return next();
  }

  // The tree's solids per bin, and no lattice value known yet.
  void loadTree(std::int32_t tree) {
    caps_.assign(unit_bins_.size(), {});
    for (std::size_t b = 0; b < unit_bins_.size(); ++b)
      if (unit_bins_[b])
        for (auto s : *unit_bins_[b])
          if (treeOf(s) == tree) caps_[b].push_back({capsuleOf(t_, s), fillet_[std::size_t(s)]});
    const std::size_t points = std::size_t(n_ * n_ * n_);
    if (stamp_.size() < points) stamp_.resize(points, 0), f_.resize(points);
    ++generation_;
  }

  // One leaf of the dual contour. Its boundary is triangulated as the conforming tetrahedra's
  // faces there (the same triangles as each neighbour's): each boundary triangle the surface
  // crosses joins its two crossed edges, so a leaf's sheets are the loops of crossings around
  // its boundary, alike in both leaves of every face. A sheet's vertex is the mean of its
  // crossings, moved onto the surface by Newton steps and kept inside the leaf.
  void dualLeaf(const OctreeLeaf& leaf, std::int32_t tree, DualUnit& out) {
    const std::int64_t size = std::int64_t(2) << leaf.level;
    const HalfPoint o{leaf.cell[0] * size, leaf.cell[1] * size, leaf.cell[2] * size};
    const HalfPoint centre{o[0] + size / 2, o[1] + size / 2, o[2] + size / 2};
    boundary_.clear();
    scratch_.clear();
    splitter_.tetrahedra(leaf, scratch_);
    if (scratch_.front()[0] == centre) {  // coned from its centre: the cones' bases
      for (const auto& tet : scratch_) boundary_.push_back({tet[1], tet[2], tet[3]});
    } else {  // Freudenthal: each face split by its diagonal from the lowest to the highest corner
      for (int a = 0; a < 3; ++a)
        for (std::int64_t side = 0; side < 2; ++side) {
          const int b = (a + 1) % 3, c = (a + 2) % 3;
          HalfPoint q[4] = {o, o, o, o};
          for (auto& p : q) p[std::size_t(a)] += side * size;
          q[1][std::size_t(b)] += size, q[2][std::size_t(b)] += size, q[2][std::size_t(c)] += size, q[3][std::size_t(c)] += size;
          boundary_.push_back({q[0], q[1], q[2]});
          boundary_.push_back({q[0], q[2], q[3]});
        }
    }
    edges_.clear();
    const auto edgeOf = [&](const HalfPoint& a, const HalfPoint& b, double fa, double fb) {
      const auto key = std::int64_t(cellCode(a[0] + b[0], a[1] + b[1], a[2] + b[2]));
      for (std::size_t k = 0; k < edges_.size(); ++k)
        if (edges_[k].key == key) return std::int32_t(k);
      edges_.push_back({key, a, b, fa, fb, std::int32_t(edges_.size())});
      return std::int32_t(edges_.size() - 1);
    };
    const auto root = [&](std::int32_t k) {
      while (edges_[std::size_t(k)].parent != k) k = edges_[std::size_t(k)].parent = edges_[std::size_t(edges_[std::size_t(k)].parent)].parent;
      return k;
    };
    segments_.clear();
    for (const auto& tri : boundary_) {
      double v[3];
      for (int q = 0; q < 3; ++q) v[q] = value(localIndex(tri[std::size_t(q)]));
      std::int32_t crossed[2], nc = 0;
      for (int q = 0; q < 3; ++q) {
        const int r = (q + 1) % 3;
        if ((v[q] < 0) != (v[r] < 0)) crossed[nc++] = edgeOf(tri[std::size_t(q)], tri[std::size_t(r)], v[q], v[r]);
      }
      if (nc != 2) continue;
      edges_[std::size_t(root(crossed[0]))].parent = root(crossed[1]);
      int face = -1;
      for (int a = 0; a < 3 && face < 0; ++a)
        if (tri[0][std::size_t(a)] == tri[1][std::size_t(a)] && tri[1][std::size_t(a)] == tri[2][std::size_t(a)])
          face = 2 * a + (tri[0][std::size_t(a)] != o[std::size_t(a)]);
      segments_.push_back({face, crossed[0], crossed[1]});
    }
    if (edges_.empty()) return;
    // Vertices, one per sheet, in the order of the sheets' first edges.
    const auto first_vertex = std::int32_t(out.vertices.size());
    sheet_of_.assign(edges_.size(), -1);
    sums_.clear();
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const auto r = std::size_t(root(std::int32_t(k)));
      if (sheet_of_[r] < 0) sheet_of_[r] = std::int32_t(sums_.size()), sums_.push_back({Vec3(0, 0, 0), 0});
      const auto& e = edges_[k];
      const double t = e.fa / (e.fa - e.fb);
      sums_[std::size_t(sheet_of_[r])].first += asVec(e.pa) + (asVec(e.pb) - asVec(e.pa)) * t;
      sums_[std::size_t(sheet_of_[r])].second += 1;
    }
    // Kept off the leaf's faces by more than the gradient's step: its samples stay in the unit's bins.
    const double margin = 2e-3 * double(size);
    const auto inLeaf = [&](const Vec3& q) {
      return componentMin(componentMax(q, asVec(o) + Vec3(margin, margin, margin)),
                          asVec(o) + Vec3(double(size) - margin, double(size) - margin, double(size) - margin));
    };
    for (const auto& [sum, count] : sums_) {
      const Vec3 q = ontoSurface(
          sum / double(count), [&](const Vec3& x) { return distance(x); }, 1e-3, 1e-7 * lat_.h, inLeaf);
      out.vertices.push_back(lat_.origin + q * (0.5 * lat_.h));
      out.steps.push_back(float(double(size) * 0.5 * lat_.h));
    }
    faceArcs(o, size, tree, out);
    // The grid edges among them (one axis): the dual polygons are made around those.
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const auto& e = edges_[k];
      int axis = -1, differ = 0;
      for (int a = 0; a < 3; ++a)
        if (e.pa[std::size_t(a)] != e.pb[std::size_t(a)]) axis = a, ++differ;
      if (differ != 1) continue;
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      const double db = double(2 * centre[std::size_t(b)] - e.pa[std::size_t(b)] - e.pb[std::size_t(b)]);
      const double dc = double(2 * centre[std::size_t(c)] - e.pa[std::size_t(c)] - e.pb[std::size_t(c)]);
      const bool low_inside = (e.pa[std::size_t(axis)] < e.pb[std::size_t(axis)]) == (e.fa < 0);
      out.records.push_back({tree, e.key, std::atan2(dc, db), first_vertex + sheet_of_[std::size_t(root(std::int32_t(k)))], low_inside});
    }
  }

  // The arcs of each face of the leaf (its segments joined within the face), where a sheet
  // crosses the face in more than one: an ArcRecord per arc, its point the mean of its crossings
  // moved onto the surface within the face.
  void faceArcs(const HalfPoint& o, std::int64_t size, std::int32_t tree, DualUnit& out) {
    const auto rootOf = [&](std::int32_t k) {
      while (edges_[std::size_t(k)].parent != k) k = edges_[std::size_t(k)].parent;
      return k;
    };
    const double margin = 2e-3 * double(size);
    for (int face = 0; face < 6; ++face) {
      arc_parent_.assign(edges_.size(), -1);
      arc_degree_.assign(edges_.size(), 0);
      int count = 0;
      for (const auto& sg : segments_) {
        if (sg.face != face) continue;
        ++count;
        for (auto e : {sg.a, sg.b}) {
          if (arc_parent_[std::size_t(e)] < 0) arc_parent_[std::size_t(e)] = e;
          ++arc_degree_[std::size_t(e)];
        }
      }
      if (count < 2) continue;
      const auto find = [&](std::int32_t k) {
        while (arc_parent_[std::size_t(k)] != k) k = arc_parent_[std::size_t(k)] = arc_parent_[std::size_t(arc_parent_[std::size_t(k)])];
        return k;
      };
      for (const auto& sg : segments_)
        if (sg.face == face) arc_parent_[std::size_t(find(sg.a))] = find(sg.b);
      // Arcs (paths: two ends of degree 1) by their root; a sheet with two or more is recorded.
      arcs_.clear();
      for (std::size_t k = 0; k < edges_.size(); ++k) {
        if (arc_parent_[k] < 0) continue;
        const auto r = find(std::int32_t(k));
        auto it = std::find_if(arcs_.begin(), arcs_.end(), [&](const LeafArc& x) { return x.root == r; });
        if (it == arcs_.end()) arcs_.push_back({r, rootOf(std::int32_t(k)), {}, 0, Vec3(0, 0, 0), 0}), it = arcs_.end() - 1;
        const auto& e = edges_[k];
        it->sum += asVec(e.pa) + (asVec(e.pb) - asVec(e.pa)) * (e.fa / (e.fa - e.fb));
        ++it->crossings;
        if (arc_degree_[k] == 1 && it->ends < 2) it->end[it->ends] = e.key;
        it->ends += arc_degree_[k] == 1;
      }
      for (const auto& arc : arcs_) {
        if (arc.ends != 2) continue;
        const auto shared = std::count_if(arcs_.begin(), arcs_.end(), [&](const LeafArc& x) { return x.sheet == arc.sheet && x.ends == 2; });
        if (shared < 2) continue;
        const int a = face / 2;
        const auto inFace = [&](const Vec3& q) {
          Vec3 c = componentMin(componentMax(q, asVec(o) + Vec3(margin, margin, margin)),
                                asVec(o) + Vec3(double(size) - margin, double(size) - margin, double(size) - margin));
          (a == 0 ? c.x : a == 1 ? c.y : c.z) = double(o[std::size_t(a)] + (face % 2) * size);
          return c;
        };
        const Vec3 q = ontoSurface(
            arc.sum / double(arc.crossings), [&](const Vec3& x) { return distance(x); }, 1e-3, 1e-7 * lat_.h, inFace);
        out.arcs.push_back({tree, std::min(arc.end[0], arc.end[1]), std::max(arc.end[0], arc.end[1]), a + 3 * (o[std::size_t(a)] + (face % 2) * size),
                            lat_.origin + q * (0.5 * lat_.h), float(double(size) * 0.5 * lat_.h)});
      }
    }
  }

  void meshTree(std::int32_t tree, UnitMesh& out) {
    loadTree(tree);
    crossings_.clear();
    keyed_.clear();
    for (const auto& tet : tets_) {
      double v[4];
      int in[4], outside[4], ni = 0, no = 0;
      for (int q = 0; q < 4; ++q) {
        v[q] = value(tet[std::size_t(q)]);
        (v[q] < 0 ? in[ni++] : outside[no++]) = q;
      }
      if (ni == 0 || no == 0) continue;
      HalfPoint p[4];
      for (int q = 0; q < 4; ++q) p[q] = halfPoint(tet[std::size_t(q)]);
      Vec3 c_in(0, 0, 0), c_out(0, 0, 0);
      for (int q = 0; q < ni; ++q) c_in += asVec(p[in[q]]) / double(ni);
      for (int q = 0; q < no; ++q) c_out += asVec(p[outside[q]]) / double(no);
      const Vec3 outward = c_out - c_in;
      const auto edge = [&](int a, int b) { return Crossing{v[a], v[b], p[a], p[b]}; };
      if (ni == 1) {
        triangle(edge(in[0], outside[0]), edge(in[0], outside[1]), edge(in[0], outside[2]), outward);
      } else if (ni == 3) {
        triangle(edge(in[0], outside[0]), edge(in[1], outside[0]), edge(in[2], outside[0]), outward);
      } else {  // a quadrilateral, in its cyclic order, as two triangles
        triangle(edge(in[0], outside[0]), edge(in[0], outside[1]), edge(in[1], outside[1]), outward);
        triangle(edge(in[0], outside[0]), edge(in[1], outside[1]), edge(in[1], outside[0]), outward);
      }
    }
    // One vertex per crossed edge, on the surface.
    std::sort(crossings_.begin(), crossings_.end(), [](const Crossing& x, const Crossing& y) { return x.key < y.key; });
    crossings_.erase(std::unique(crossings_.begin(), crossings_.end(), [](const Crossing& x, const Crossing& y) { return x.key == y.key; }),
                     crossings_.end());
    const auto base = std::int32_t(out.vertices.size());
    keys_.clear();
    for (const auto& c : crossings_) {
      const double t = std::clamp(zeroOnEdge(asVec(c.pa), asVec(c.pb), c.fa, c.fb), kEdgeMargin, 1 - kEdgeMargin);
      const Vec3 pa = lat_.position(c.pa), pb = lat_.position(c.pb);
      out.vertices.push_back({{tree, c.key}, pa + (pb - pa) * t, pb - pa, t});
      keys_.push_back(c.key);
    }
    // Triangles by their vertices' index in the unit.
    const auto local = [&](std::int64_t edge) { return base + std::int32_t(std::lower_bound(keys_.begin(), keys_.end(), edge) - keys_.begin()); };
    for (const auto& k : keyed_) {
      out.triangles.push_back({local(k.edge[0]), local(k.edge[1]), local(k.edge[2])});
      out.triangle_tree.push_back(tree);
    }
  }

  struct Crossing {
    std::int64_t key;  // the edge's midpoint in quarter steps, packed
    HalfPoint pa, pb;  // inside, outside
    double fa, fb;
    Crossing(double va, double vb, const HalfPoint& a, const HalfPoint& b) : pa(a), pb(b), fa(va), fb(vb) {
      key = std::int64_t(cellCode(a[0] + b[0], a[1] + b[1], a[2] + b[2]));
    }
  };
  static Vec3 asVec(const HalfPoint& q) { return Vec3(double(q[0]), double(q[1]), double(q[2])); }

  // The triangle's turn is that of the edges' midpoints (exact in half steps): a vertex moves
  // along its edge's open interior, where the triangle never degenerates, so the turn holds.
  void triangle(const Crossing& e0, const Crossing& e1, const Crossing& e2, const Vec3& outward) {
    const Vec3 m0 = asVec(e0.pa) + asVec(e0.pb), m1 = asVec(e1.pa) + asVec(e1.pb), m2 = asVec(e2.pa) + asVec(e2.pb);
    const bool flip = dot(cross(m1 - m0, m2 - m0), outward) < 0;
    keyed_.push_back({{e0.key, flip ? e2.key : e1.key, flip ? e1.key : e2.key}});
    crossings_.push_back(e0);
    crossings_.push_back(e1);
    crossings_.push_back(e2);
  }

  const VascularTree& t_;
  const Lattice& lat_;
  LeafSplitter& splitter_;
  const std::vector<double>& fillet_;
  int shift_ = 0;
  std::int64_t n_ = 0;
  HalfPoint base_{};
  std::array<std::int64_t, 3> bin_lo_{}, bin_n_{};
  std::vector<const std::vector<std::int32_t>*> unit_bins_;
  std::vector<std::vector<Solid>> caps_;  // per unit bin, the current tree's
  std::vector<std::array<HalfPoint, 4>> scratch_;
  std::vector<std::array<std::int32_t, 4>> tets_;
  std::vector<std::uint32_t> stamp_;
  std::vector<double> f_;
  std::uint32_t generation_ = 0;
  std::vector<Crossing> crossings_;
  std::vector<KeyedTriangle> keyed_;  // the current tree's, by their edges
  std::vector<std::int64_t> keys_;    // the current tree's crossed edges, in order
  // The dual contour's per-leaf scratch.
  struct LeafEdge {
    std::int64_t key;
    HalfPoint pa, pb;
    double fa, fb;
    std::int32_t parent;  // union-find: edges joined across the boundary's triangles
  };
  struct Segment {
    int face;           // 2 × axis + side
    std::int32_t a, b;  // its crossed edges
  };
  struct LeafArc {
    std::int32_t root, sheet;  // in the face's union-find; the leaf's sheet
    std::int64_t end[2];
    int ends;
    Vec3 sum;
    int crossings;
  };
  std::vector<std::array<HalfPoint, 3>> boundary_;
  std::vector<LeafEdge> edges_;
  std::vector<Segment> segments_;
  std::vector<std::int32_t> arc_parent_, arc_degree_;
  std::vector<LeafArc> arcs_;
  std::vector<std::int32_t> sheet_of_;
  std::vector<std::pair<Vec3, int>> sums_;
};

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

// Drops the components whose representative vertex (componentOf) is flagged in `drop`. Returns
// how many.
std::int64_t dropComponents(SurfaceMesh& m, const std::vector<std::int32_t>& component, const std::vector<char>& drop) {
  const auto removed = std::int64_t(std::count(drop.begin(), drop.end(), 1));
  if (removed == 0) return 0;
  std::vector<char> keep(m.triangles.size());
  for (std::size_t k = 0; k < m.triangles.size(); ++k) keep[k] = !drop[std::size_t(component[std::size_t(m.triangles[k][0])])];
  keepTriangles(m, keep);
  return removed;
}

// Drops the closed components that enclose a negative volume: pockets of outside space the grid
// cannot resolve (a wedge between two vessels closed off between grid points), which the union
// of a tree's vessels does not have. Returns how many.
std::int64_t removeCavities(SurfaceMesh& m) {
  const auto component = componentOf(m);
  std::vector<double> volume(m.vertices.size(), 0.0);  // per component representative: 6 × its signed volume
  for (const auto& t : m.triangles)
    volume[std::size_t(component[std::size_t(t[0])])] += dot(m.vertices[t[0]], cross(m.vertices[t[1]], m.vertices[t[2]]));
  std::vector<char> drop(volume.size(), 0);
  for (std::size_t v = 0; v < volume.size(); ++v) drop[v] = component[v] == std::int32_t(v) && volume[v] < 0;
  return dropComponents(m, component, drop);
}

bool hasGapPartners(const SurfaceOptions& o, std::int32_t s) {
  return std::size_t(s) < o.vessel_gap_partners.size() && !o.vessel_gap_partners[std::size_t(s)].empty();
}

// Each vessel's level (cells of 2^level steps h): the coarsest that puts samples_across samples
// across its thinnest end. (The volume the coarser chords of thick vessels lose is restored
// after contouring, restoreVolume.) `away_from_gaps`: a vessel with gap partners at its own
// level, without its gap's bound (which holds only near them).
std::vector<std::int8_t> vesselLevels(const VascularTree& t, const std::vector<std::int32_t>& vessels, double h, const SurfaceOptions& o,
                                      bool away_from_gaps = false) {
  std::vector<std::int8_t> level(std::size_t(t.nodeCount()), 0);
  if (!o.adaptive) return level;
  for (auto s : vessels) {
    double c = 2 * std::min(t.radius[s], t.startRadius(s)) / std::max(1, o.samples_across);
    if (o.max_cell_mm > 0) c = std::min(c, o.max_cell_mm);
    if (std::size_t(s) < o.vessel_max_cell_mm.size() && o.vessel_max_cell_mm[std::size_t(s)] > 0 && !(away_from_gaps && hasGapPartners(o, s)))
      c = std::min(c, o.vessel_max_cell_mm[std::size_t(s)]);
    if (c >= 2 * h) level[std::size_t(s)] = std::int8_t(std::min(kMaxSurfaceLevel, int(std::floor(std::log2(c / h) + 1e-9))));
  }
  return level;
}

// Per vertex, over its triangles: the area-weighted normal (× 2), the area, and the area-weighted
// gap of the triangles' centroids (¾ of their distance inside: what flat chords lose).
struct ChordGaps {
  std::vector<Vec3> normal;
  std::vector<double> weighted, area;
};
ChordGaps chordGaps(const SurfaceMesh& m, const std::function<double(std::int32_t, const Vec3&)>& distance) {
  const std::size_t nt = m.triangles.size();
  std::vector<double> gap(nt, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nt, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      const auto& t = m.triangles[k];
      const Vec3 c = (m.vertices[std::size_t(t[0])] + m.vertices[std::size_t(t[1])] + m.vertices[std::size_t(t[2])]) / 3.0;
      const double d = distance(m.triangle_tree[k], c);
      gap[k] = std::isfinite(d) ? -0.75 * d : 0.0;
    }
  });
  ChordGaps g{std::vector<Vec3>(m.vertices.size(), Vec3(0, 0, 0)), std::vector<double>(m.vertices.size(), 0.0),
              std::vector<double>(m.vertices.size(), 0.0)};
  for (std::size_t k = 0; k < nt; ++k) {
    const auto& t = m.triangles[k];
    const Vec3 n =
        cross(m.vertices[std::size_t(t[1])] - m.vertices[std::size_t(t[0])], m.vertices[std::size_t(t[2])] - m.vertices[std::size_t(t[0])]);
    const double a = norm(n);
    for (auto v : t) g.normal[std::size_t(v)] += n, g.weighted[std::size_t(v)] += a * gap[k], g.area[std::size_t(v)] += a;
  }
  return g;
}

// Flat triangles through points of a vessel's surface lie inside it where it is convex (chords)
// and lose volume: about c²/(12 r²) of a vessel sampled by cells of size c (more where cells are
// coarse); at creases they stand out. Each triangle's gap is measured at its centroid with the
// exact distance; over a triangle whose corners lie on the surface the gap averages ¾ of that
// (a quadratic vanishing at the corners), so moving each vertex outwards by ¾ of the
// area-weighted gap of its triangles restores the enclosed volume. A vertex slides along its
// own edge of the tetrahedra (by the move over the edge's outward component, within the edge's
// inner 98 % and at most a fifth of it): every triangle stays inside its tetrahedron, so the surface keeps free of
// self-intersections. The move is a fraction of the chord's sagitta. Returns the largest.
constexpr double kLargestSlide = 0.2;
// Rounds of relax() for the dual contour's folds.
constexpr int kRelaxRounds = 4;  // share of the edge: a grazing edge would carry the vertex far from the surface

double restoreVolume(SurfaceMesh& m, const std::vector<Vec3>& along, std::vector<double>& on_edge,
                     const std::function<double(std::int32_t, const Vec3&)>& distance) {
  const auto [normal, weighted, area] = chordGaps(m, distance);
  double largest = 0;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    const double outward = dot(along[v], unit(normal[v]));
    if (!(area[v] > 0) || !(outward > 0)) continue;
    const Vec3 start = m.vertices[v] - along[v] * on_edge[v];
    const double slide = std::clamp(weighted[v] / area[v] / outward, -kLargestSlide, kLargestSlide);
    const double t = std::clamp(on_edge[v] + slide, kEdgeMargin, 1 - kEdgeMargin);
    largest = std::max(largest, std::abs(t - on_edge[v]) * norm(along[v]));
    on_edge[v] = t;
    m.vertices[v] = start + along[v] * t;
  }
  return largest;
}

// Runs fn(mesher, unit index, the unit's leaves) over the units in parallel, in batches so that
// progress is reported from the calling thread.
template <class F>
void forEachUnit(const VascularTree& t, const Lattice& lat, const BalancedOctree& octree, const std::vector<OctreeLeaf>& units,
                 const std::vector<double>& fillet, const std::function<void(std::int64_t, std::int64_t)>& progress, const F& fn) {
  const std::int64_t nu = std::int64_t(units.size()), batch = 4096;
  for (std::int64_t first = 0; first < nu; first += batch) {
    const std::int64_t last = std::min(nu, first + batch);
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(first, last, 4), [&](const tbb::blocked_range<std::int64_t>& r) {
      LeafSplitter splitter(octree);
      UnitMesher mesher(t, lat, splitter, fillet);
      std::vector<OctreeLeaf> leaves;
      for (std::int64_t u = r.begin(); u != r.end(); ++u) {
        splitter.leaves(units[std::size_t(u)], leaves);
        fn(mesher, std::size_t(u), leaves);
      }
    });
    if (progress) progress(last, nu);
  }
}

// Where a coarse leaf meets finer ones, or the surface grazes a face, a sheet's vertex may lie
// so far round the surface that a triangle folds back over its neighbours. The corners of the
// triangles marked (facing against the summed normal at one of their corners, or found crossing
// another) move to the mean of their neighbours and back onto the surface (Newton steps on the
// distance). Returns the vertices moved.
std::int64_t relax(SurfaceMesh& m, const std::vector<std::int32_t>& tree_of, const std::vector<std::int32_t>& marked_triangles,
                   const std::function<double(std::int32_t, const Vec3&)>& distance) {
  const std::size_t nv = m.vertices.size(), nt = m.triangles.size();
  std::vector<char> bad(nv, 0);
  for (auto k : marked_triangles)
    for (auto w : m.triangles[std::size_t(k)]) bad[std::size_t(w)] = 1;
  {
    std::vector<Vec3> normal(nv, Vec3(0, 0, 0)), face(nt);
    for (std::size_t k = 0; k < nt; ++k) {
      const auto& t = m.triangles[k];
      face[k] = cross(m.vertices[std::size_t(t[1])] - m.vertices[std::size_t(t[0])], m.vertices[std::size_t(t[2])] - m.vertices[std::size_t(t[0])]);
      for (auto v : t) normal[std::size_t(v)] += face[k];
    }
    for (std::size_t k = 0; k < nt; ++k)
      for (auto v : m.triangles[k])
        if (dot(face[k], normal[std::size_t(v)]) <= 0) {
          for (auto w : m.triangles[k]) bad[std::size_t(w)] = 1;
          break;
        }
  }
  std::vector<Vec3> sum(nv, Vec3(0, 0, 0));
  std::vector<int> count(nv, 0);
  for (const auto& t : m.triangles)
    for (int q = 0; q < 3; ++q)
      if (bad[std::size_t(t[std::size_t(q)])])
        for (int r = 1; r < 3; ++r)
          sum[std::size_t(t[std::size_t(q)])] += m.vertices[std::size_t(t[std::size_t((q + r) % 3)])], ++count[std::size_t(t[std::size_t(q)])];
  std::int64_t moved = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    if (!bad[v] || count[v] == 0) continue;
    const auto tree = tree_of[v];
    const Vec3 p = ontoSurface(
        sum[v] / double(count[v]), [&](const Vec3& x) { return distance(tree, x); }, 1e-3 * m.vertex_step[v], 1e-6 * m.vertex_step[v],
        [](const Vec3& x) { return x; });
    m.vertices[v] = p;
    ++moved;
  }
  return moved;
}

// A corner of a crossing triangle with only three triangles round it (a knot of vertices a
// hundredth of a step apart, which Laplace steps hardly move) goes: its three triangles become the
// one of their outer corners (the Euler characteristic stays), unless that triangle is there
// already. The vertices stay, unused (keepTriangles drops them). True if any went; then `dirty`
// flags, in the new numbering, the crossing triangles that stayed and the new ones (the rest did
// not change, so their pairs need no second check).
bool removeThreeFans(SurfaceMesh& m, const std::vector<std::int32_t>& crossing, std::vector<char>& dirty) {
  // The triangles around the crossing triangles' corners and their neighbours only.
  std::vector<std::int32_t> slot(m.vertices.size(), -1);
  std::vector<std::vector<std::int32_t>> around;
  const auto watch = [&](std::int32_t v) {
    if (slot[std::size_t(v)] < 0) slot[std::size_t(v)] = std::int32_t(around.size()), around.emplace_back();
  };
  std::vector<char> corner(m.vertices.size(), 0);
  for (auto k : crossing)
    for (auto v : m.triangles[std::size_t(k)]) corner[std::size_t(v)] = 1;
  for (const auto& t : m.triangles)
    if (corner[std::size_t(t[0])] || corner[std::size_t(t[1])] || corner[std::size_t(t[2])])
      for (auto v : t) watch(v);
  for (std::size_t k = 0; k < m.triangles.size(); ++k)
    for (auto v : m.triangles[k])
      if (slot[std::size_t(v)] >= 0) around[std::size_t(slot[std::size_t(v)])].push_back(std::int32_t(k));
  const auto fanOf = [&](std::int32_t v) -> const std::vector<std::int32_t>& { return around[std::size_t(slot[std::size_t(v)])]; };
  const std::size_t first_added = m.triangles.size();
  std::vector<char> keep(first_added, 1);
  const auto same = [](std::array<std::int32_t, 3> x, std::array<std::int32_t, 3> y) {
    std::sort(x.begin(), x.end());
    std::sort(y.begin(), y.end());
    return x == y;
  };
  bool any = false;
  for (auto k : crossing)
    for (auto v : m.triangles[std::size_t(k)]) {
      const auto& fan = fanOf(v);
      if (fan.size() != 3 || !keep[std::size_t(fan[0])] || !keep[std::size_t(fan[1])] || !keep[std::size_t(fan[2])]) continue;
      // The link: each triangle (v, x, y) gives x → y.
      std::int32_t next_of[3][2];
      for (int q = 0; q < 3; ++q) {
        const auto& t = m.triangles[std::size_t(fan[std::size_t(q)])];
        const int at = t[0] == v ? 0 : t[1] == v ? 1 : 2;
        next_of[q][0] = t[std::size_t((at + 1) % 3)], next_of[q][1] = t[std::size_t((at + 2) % 3)];
      }
      const std::int32_t a = next_of[0][0], b = next_of[0][1];
      std::int32_t c = -1;
      for (int q = 1; q < 3; ++q)
        if (next_of[q][0] == b) c = next_of[q][1];
      if (c < 0 || c == a) continue;
      const std::array<std::int32_t, 3> cap{a, b, c};
      bool there = false;
      for (auto t : fanOf(a)) there = there || (keep[std::size_t(t)] && same(m.triangles[std::size_t(t)], cap));
      if (there) continue;
      for (auto t : fan) keep[std::size_t(t)] = 0;
      m.triangles.push_back(cap);
      m.triangle_tree.push_back(m.triangle_tree[std::size_t(fan[0])]);
      keep.push_back(1);
      for (auto x : cap) around[std::size_t(slot[std::size_t(x)])].push_back(std::int32_t(m.triangles.size() - 1));
      any = true;
    }
  if (!any) return false;
  std::vector<char> was(first_added, 0);
  for (auto k : crossing) was[std::size_t(k)] = 1;
  dirty.clear();
  for (std::size_t k = 0; k < keep.size(); ++k)
    if (keep[k]) dirty.push_back(k < first_added ? was[k] : 1);
  keepTriangles(m, keep);
  return true;
}

// Rounds of untangle() after relax (each a ring wider: the largest parts of the 100k-segment
// benchmark tree keep a knot of crossing triangles through most of them), and how far off the
// surface it may leave a vertex (of its step; every vertex stays within half a step).
constexpr int kUntangleRounds = 8;
constexpr double kUntangleOffset = 0.4;

// Where folds cross at creases and thin gaps closer than a fifth of a step, moving the corners
// back onto the surface (relax) makes the same crossing again. The corners of the crossing
// triangles and `rings` rings of vertices around them move three times to the mean of their
// neighbours (Laplace steps untangle a fold) and, where that leaves one more than
// kUntangleOffset of its step off the surface, back to that offset (Newton steps on the distance
// less the offset).
void untangle(SurfaceMesh& m, const std::vector<std::int32_t>& tree_of, const std::vector<std::int32_t>& crossing, int rings,
              const std::function<double(std::int32_t, const Vec3&)>& distance) {
  std::vector<std::vector<std::int32_t>> next_to(m.vertices.size());
  for (const auto& t : m.triangles)
    for (int q = 0; q < 3; ++q) next_to[std::size_t(t[std::size_t(q)])].push_back(t[std::size_t((q + 1) % 3)]);
  std::vector<char> in(m.vertices.size(), 0);
  std::vector<std::int32_t> moving;
  for (auto k : crossing)
    for (auto v : m.triangles[std::size_t(k)])
      if (!in[std::size_t(v)]) in[std::size_t(v)] = 1, moving.push_back(v);
  for (int r = 0; r < rings; ++r)
    for (std::size_t i = 0, n = moving.size(); i < n; ++i)
      for (auto w : next_to[std::size_t(moving[i])])
        if (!in[std::size_t(w)]) in[std::size_t(w)] = 1, moving.push_back(w);
  std::vector<Vec3> to(moving.size());
  for (int step = 0; step < 3; ++step) {
    for (std::size_t i = 0; i < moving.size(); ++i) {
      Vec3 sum(0, 0, 0);
      for (auto w : next_to[std::size_t(moving[i])]) sum += m.vertices[std::size_t(w)];
      to[i] = sum / double(next_to[std::size_t(moving[i])].size());
    }
    for (std::size_t i = 0; i < moving.size(); ++i) {
      const auto v = std::size_t(moving[i]);
      const auto tree = tree_of[v];
      const double h = m.vertex_step[v], most = kUntangleOffset * h, d = distance(tree, to[i]);
      if (std::abs(d) > most) {
        const double offset = d > 0 ? most : -most;
        to[i] = ontoSurface(
            to[i], [&](const Vec3& x) { return distance(tree, x) - offset; }, 1e-3 * h, 1e-3 * h, [](const Vec3& x) { return x; });
      }
      m.vertices[v] = to[i];
    }
  }
}

// A sheet whose loop crosses only two grid edges gets a vertex of two triangles on the same
// three vertices, back to back: a flat pillow. Both go (with the vertex); the surface around
// them closes over their shared edge. Repeated while removing one makes another.
void removePillows(SurfaceMesh& m) {
  for (;;) {
    std::vector<std::int32_t> degree(m.vertices.size(), 0), any(m.vertices.size(), -1);
    for (std::size_t k = 0; k < m.triangles.size(); ++k)
      for (auto v : m.triangles[k]) ++degree[std::size_t(v)], any[std::size_t(v)] = std::int32_t(k);
    std::vector<char> keep(m.triangles.size(), 1);
    std::vector<std::array<std::int32_t, 3>> sorted(m.triangles.size());
    for (std::size_t k = 0; k < m.triangles.size(); ++k) {
      sorted[k] = m.triangles[k];
      std::sort(sorted[k].begin(), sorted[k].end());
    }
    bool removed = false;
    // The two triangles of a degree-2 vertex: the last one found and the other.
    std::vector<std::int32_t> second(m.vertices.size(), -1);
    for (std::size_t k = 0; k < m.triangles.size(); ++k)
      for (auto v : m.triangles[k])
        if (degree[std::size_t(v)] == 2 && any[std::size_t(v)] != std::int32_t(k)) second[std::size_t(v)] = std::int32_t(k);
    for (std::size_t v = 0; v < m.vertices.size(); ++v) {
      if (degree[v] != 2 || second[v] < 0) continue;
      const auto a = std::size_t(any[v]), b = std::size_t(second[v]);
      if (!keep[a] || !keep[b] || sorted[a] != sorted[b]) continue;
      keep[a] = keep[b] = 0;
      removed = true;
    }
    if (!removed) return;
    keepTriangles(m, keep);
  }
}

// A polygon of the dual contour: the leaves' vertices around a crossed grid edge, counter-clockwise
// seen from outside, and maybe an arc's vertex.
struct DualPolygon {
  std::int32_t v[5];
  int n;
  std::int32_t tree;
  std::int64_t edge;
};

// A triangle, or a quadrilateral split along the diagonal that folds it least.
void appendPolygon(SurfaceMesh& mesh, const DualPolygon& p) {
  if (p.n == 3) {
    mesh.triangles.push_back({p.v[0], p.v[1], p.v[2]});
  } else {
    const std::int32_t q[4] = {p.v[0], p.v[1], p.v[2], p.v[3]};
    appendQuad(mesh, q);
    mesh.triangle_tree.push_back(p.tree);
  }
  mesh.triangle_tree.push_back(p.tree);
}

// The polygons around grid edges arcs end on. Two of them that run across the same pair of
// vertices the same way hold two arcs of one face between the same two sheets: each arc's vertex
// goes between the pair in the two polygons at its ends (which run across it opposite ways), and
// such a polygon is a fan from it, so each new edge has two triangles and the pair none. False
// (and why) where the arcs cannot be told apart.
bool splitSharedPairs(SurfaceMesh& mesh, std::vector<DualPolygon>& held, const std::vector<ArcRecord>& arcs, const char*& refused) {
  struct Use {
    std::int32_t a, b;
    std::int32_t polygon, at;
  };
  std::vector<Use> uses;
  for (std::size_t p = 0; p < held.size(); ++p)
    for (int k = 0; k < held[p].n; ++k) uses.push_back({held[p].v[k], held[p].v[(k + 1) % held[p].n], std::int32_t(p), k});
  std::sort(uses.begin(), uses.end(), [](const Use& x, const Use& y) { return std::tie(x.a, x.b, x.polygon) < std::tie(y.a, y.b, y.polygon); });
  const auto range = [&](std::int32_t a, std::int32_t b) {
    const auto lo = std::lower_bound(
        uses.begin(), uses.end(), std::make_pair(a, b),
        [](const Use& u, const std::pair<std::int32_t, std::int32_t>& k) { return std::tie(u.a, u.b) < std::tie(k.first, k.second); });
    auto hi = lo;
    while (hi != uses.end() && hi->a == a && hi->b == b) ++hi;
    return std::make_pair(lo, hi);
  };
  // The arcs (of any face) between grid edges e and f.
  const auto arcsOf = [&](std::int32_t tree, std::int64_t e, std::int64_t f) {
    const auto key = std::make_tuple(tree, std::min(e, f), std::max(e, f));
    const auto cmp = [](const ArcRecord& r, const std::tuple<std::int32_t, std::int64_t, std::int64_t>& k) {
      return std::tie(r.tree, r.lo, r.hi) < k;
    };
    auto lo = std::lower_bound(arcs.begin(), arcs.end(), key, cmp), hi = lo;
    while (hi != arcs.end() && std::tie(hi->tree, hi->lo, hi->hi) == key) ++hi;
    return std::make_pair(lo, hi);
  };
  std::vector<std::vector<std::pair<std::int32_t, std::int32_t>>> split(held.size());  // per polygon: (at, arc vertex)
  for (auto it = uses.begin(); it != uses.end();) {
    // (Iterators, not a structured binding: the lambdas below capture them.)
    const auto forward = range(it->a, it->b);
    const auto first = forward.first, last = forward.second;
    it = last;
    if (last - first < 2 || first->a > first->b) continue;
    const auto backward = range(first->b, first->a);
    const auto rfirst = backward.first, rlast = backward.second;
    if (last - first != 2 || rlast - rfirst != 2) {
      refused = "more than two arcs between two sheets";
      return false;
    }
    // The face's plane: the one in which each forward polygon's edge has an arc to one backward
    // polygon's edge, a different one for each (an edge also ends arcs on the other faces
    // through it, and two edges on one line end arcs on two faces).
    const auto edgeOf = [&](const Use& u) { return held[std::size_t(u.polygon)].edge; };
    const std::int32_t tree = held[std::size_t(first->polygon)].tree;
    std::vector<std::int64_t> planes;
    for (int f = 0; f < 2; ++f)
      for (int g = 0; g < 2; ++g)
        for (auto [lo, hi] = arcsOf(tree, edgeOf(first[f]), edgeOf(rfirst[g])); lo != hi; ++lo) planes.push_back(lo->plane);
    std::sort(planes.begin(), planes.end());
    planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
    const ArcRecord* chosen[2] = {nullptr, nullptr};
    int matched[2] = {-1, -1}, faces = 0;
    for (auto plane : planes) {
      const auto inPlane = [&](int f, int g) -> const ArcRecord* {
        for (auto [lo, hi] = arcsOf(tree, edgeOf(first[f]), edgeOf(rfirst[g])); lo != hi; ++lo)
          if (lo->plane == plane) return &*lo;
        return nullptr;
      };
      for (int g = 0; g < 2; ++g) {
        const auto *x = inPlane(0, g), *y = inPlane(1, 1 - g);
        if (!x || !y || inPlane(0, 1 - g) || inPlane(1, g)) continue;
        chosen[0] = x, chosen[1] = y, matched[0] = g, matched[1] = 1 - g, ++faces;
      }
    }
    if (faces != 1) {
      refused = "two arcs between two sheets not told apart";
      return false;
    }
    for (int f = 0; f < 2; ++f) {
      const ArcRecord* arc = chosen[f];
      const int match = matched[f];
      const auto m = std::int32_t(mesh.vertices.size());
      mesh.vertices.push_back(arc->position);
      mesh.vertex_step.push_back(arc->step);
      for (const Use* u : {&first[f], &rfirst[match]}) split[std::size_t(u->polygon)].push_back({u->at, m});
    }
  }
  std::vector<std::int32_t> ring;
  for (std::size_t p = 0; p < held.size(); ++p) {
    const auto& poly = held[p];
    if (split[p].empty()) {
      appendPolygon(mesh, poly);
      continue;
    }
    // The polygon with its arcs' vertices, each after vertex `at`, as a fan from the first of
    // them (the others on its rim, their edges each in two triangles).
    std::sort(split[p].begin(), split[p].end());
    ring.clear();
    std::size_t next = 0, apex = 0;
    for (int k = 0; k < poly.n; ++k) {
      ring.push_back(poly.v[k]);
      if (next < split[p].size() && split[p][next].first == k) {
        if (next == 0) apex = ring.size();
        ring.push_back(split[p][next++].second);
      }
    }
    for (std::size_t k = 1; k + 1 < ring.size(); ++k) {
      mesh.triangles.push_back({ring[apex], ring[(apex + k) % ring.size()], ring[(apex + k + 1) % ring.size()]});
      mesh.triangle_tree.push_back(poly.tree);
    }
  }
  return true;
}

// The dual contour of the octree's leaves (surface nets): a vertex per sheet of each leaf, a
// triangle or quadrilateral around each grid edge the surface crosses from the 3 or 4 leaves
// around it (a coarser leaf spans two of its quadrants), counter-clockwise seen from outside,
// a quadrilateral split along the diagonal that folds it least. Null (and why) where an edge's
// leaves do not close around it.
std::optional<SurfaceMesh> dualContour(const VascularTree& t, const Lattice& lat, const BalancedOctree& octree, const std::vector<OctreeLeaf>& units,
                                       const std::vector<double>& fillet, const char*& refused,
                                       const std::function<void(std::int64_t, std::int64_t)>& progress) {
  std::vector<DualUnit> duals(units.size());
  forEachUnit(t, lat, octree, units, fillet, progress, [&](UnitMesher& mesher, std::size_t u, const std::vector<OctreeLeaf>& leaves) {
    mesher.dual(units[u].level, units[u].cell, leaves.data(), leaves.data() + leaves.size(), duals[u]);
  });
  SurfaceMesh mesh;
  std::vector<DualRecord> records;
  std::vector<ArcRecord> arcs;
  for (auto& d : duals) {
    const auto base = std::int32_t(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), d.vertices.begin(), d.vertices.end());
    mesh.vertex_step.insert(mesh.vertex_step.end(), d.steps.begin(), d.steps.end());
    for (auto r : d.records) r.vertex += base, records.push_back(r);
    arcs.insert(arcs.end(), d.arcs.begin(), d.arcs.end());
    DualUnit().records.swap(d.records);
  }
  tbb::parallel_sort(records.begin(), records.end(),
                     [](const DualRecord& a, const DualRecord& b) { return std::tie(a.tree, a.edge, a.angle) < std::tie(b.tree, b.edge, b.angle); });
  // Each arc once (both leaves of its face may record it; the first by position, whatever the
  // units' order), and the grid edges arcs end on: only polygons around those can share a pair.
  const auto arcKey = [](const ArcRecord& a) { return std::tie(a.tree, a.lo, a.hi, a.plane); };
  std::sort(arcs.begin(), arcs.end(), [&](const ArcRecord& a, const ArcRecord& b) {
    return std::tie(a.tree, a.lo, a.hi, a.plane, a.position.x, a.position.y, a.position.z) <
           std::tie(b.tree, b.lo, b.hi, b.plane, b.position.x, b.position.y, b.position.z);
  });
  arcs.erase(std::unique(arcs.begin(), arcs.end(), [&](const ArcRecord& a, const ArcRecord& b) { return arcKey(a) == arcKey(b); }), arcs.end());
  std::vector<std::pair<std::int32_t, std::int64_t>> arc_ends;
  for (const auto& a : arcs) arc_ends.push_back({a.tree, a.lo}), arc_ends.push_back({a.tree, a.hi});
  std::sort(arc_ends.begin(), arc_ends.end());
  std::vector<DualPolygon> held;  // polygons around an arc's end: made last
  for (std::size_t i = 0; i < records.size();) {
    std::size_t j = i;
    while (j < records.size() && records[j].tree == records[i].tree && records[j].edge == records[i].edge) ++j;
    const std::size_t n = j - i;
    if (n == 2) {  // an edge inside a face (a fan's spoke): no polygon
      i = j;
      continue;
    }
    if (n != 3 && n != 4) {
      refused = "an edge without 3 or 4 leaves around it";
      return std::nullopt;
    }
    DualPolygon poly{{}, int(n), records[i].tree, records[i].edge};
    for (std::size_t k = 0; k < n; ++k) poly.v[k] = records[i + k].vertex;
    if (!records[i].low_inside) std::reverse(poly.v, poly.v + n);  // outward is down the edge's axis
    i = j;
    if (std::binary_search(arc_ends.begin(), arc_ends.end(), std::make_pair(poly.tree, poly.edge))) {
      held.push_back(poly);
      continue;
    }
    appendPolygon(mesh, poly);
  }
  if (!splitSharedPairs(mesh, held, arcs, refused)) return std::nullopt;
  removePillows(mesh);
  return mesh;
}
}  // namespace

constexpr double kSpeckSteps = 0.25;

std::int64_t removeSpecks(SurfaceMesh& m) {
  if (m.vertex_step.size() != m.vertices.size()) return 0;
  const auto component = componentOf(m);
  const std::size_t nv = m.vertices.size();
  std::vector<Vec3> lo(nv, Vec3(INFINITY, INFINITY, INFINITY)), hi(nv, Vec3(-INFINITY, -INFINITY, -INFINITY));
  std::vector<double> step(nv, INFINITY);
  std::vector<char> used(nv, 0);
  for (const auto& t : m.triangles)
    for (auto v : t) used[std::size_t(v)] = 1;
  for (std::size_t v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    const auto c = std::size_t(component[v]);
    lo[c] = componentMin(lo[c], m.vertices[v]), hi[c] = componentMax(hi[c], m.vertices[v]);
    step[c] = std::min(step[c], double(m.vertex_step[v]));
  }
  std::vector<char> speck(nv, 0);
  for (std::size_t c = 0; c < nv; ++c)
    if (used[c] && component[c] == std::int32_t(c)) {
      const Vec3 extent = hi[c] - lo[c];
      speck[c] = std::max({extent.x, extent.y, extent.z}) < kSpeckSteps * step[c];
    }
  return dropComponents(m, component, speck);
}

double restoreVolumeAlongNormals(SurfaceMesh& m, const std::function<double(std::int32_t, const Vec3&)>& distance) {
  const auto [normal, weighted, area] = chordGaps(m, distance);
  double largest = 0;
  for (std::size_t v = 0; v < m.vertices.size(); ++v) {
    if (!(area[v] > 0)) continue;
    const double step = m.vertex_step[v], move = std::clamp(weighted[v] / area[v], -kLargestSlide * step, kLargestSlide * step);
    m.vertices[v] += unit(normal[v]) * move;
    largest = std::max(largest, std::abs(move));
  }
  return largest;
}

namespace {

// The contour's grid: the vessels, the finest step, each vessel's finest cells (at gaps) and
// coarse cells (elsewhere), the fillets, the top level, and the lattice with its bins.
struct ContourPlan {
  std::vector<std::int32_t> vessels;  // none: nothing to contour
  double h = 0;
  std::vector<std::int8_t> level, coarse;
  std::vector<double> fillet;
  int top = 0;
  Lattice lat;
  double cellSize(int l) const { return h * double(std::int64_t(1) << l); }
};

// Throws InputError past the memory limit or the lattice's index range.
ContourPlan planContour(const VascularTree& t, const SurfaceOptions& o, SurfaceReport* report) {
  ContourPlan plan;
  Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  double r_min = INFINITY;
  std::vector<std::int32_t> vessels;
  for (std::int32_t s = 0; s < t.nodeCount(); ++s) {
    if (t.isRoot(s) || t.isLink(s)) continue;  // a link lies inside the cap of the vessel ending at its junction
    vessels.push_back(s);
    const double r = t.maxRadius(s);
    r_min = std::min({r_min, t.radius[s], t.startRadius(s)});
    for (const Vec3& p : {t.position[t.parent[s]], t.position[s]}) {
      lo = componentMin(lo, p - Vec3(r, r, r));
      hi = componentMax(hi, p + Vec3(r, r, r));
    }
  }
  if (vessels.empty()) return plan;
  if (!(r_min > 0)) throw InputError("", 0, "a vessel of radius 0 has no surface; every radius must be > 0");
  const int across = std::max(1, o.samples_across);
  double h = o.voxel_mm > 0 ? o.voxel_mm : o.max_cell_mm > 0 ? std::min(2 * r_min / across, o.max_cell_mm) : 2 * r_min / across;
  if (!(o.voxel_mm > 0))
    for (auto c : o.vessel_max_cell_mm)
      if (c > 0) h = std::min(h, c);
  // `level`: the finest cells a vessel gets (and its fillet's width); `coarse`: those it gets
  // away from a gap (the same without gap partners).
  auto level = vesselLevels(t, vessels, h, o), coarse = vesselLevels(t, vessels, h, o, true);
  std::vector<double> fillet(std::size_t(t.nodeCount()), 0.0);
  for (auto s : vessels) fillet[std::size_t(s)] = kFillet * h * double(std::int64_t(1) << level[std::size_t(s)]);
  int top = 0;
  for (auto s : vessels) top = std::max<int>(top, coarse[std::size_t(s)]);
  const auto cellSize = [&](int l) { return h * double(std::int64_t(1) << l); };
  // Room around the vessels for the requested cells (up to two cells of their level beyond the
  // vessel) and the coarsest cells the balance adds around them (two of level top + 1); midpoints
  // of edges in quarter steps must fit 21 bits.
  const double room = 6 * cellSize(top + 1);
  Lattice lat;
  lat.h = h;
  lat.origin = lo - Vec3(room, room, room);
  std::int64_t steps[3];
  for (int a = 0; a < 3; ++a) {
    const double n = std::ceil((hi[a] - lo[a] + 2 * room) / h) + 1;
    if (!(n < double(std::int64_t(1) << 19)))
      throw InputError("", 0,
                       "a surface step of " + std::to_string(h) + " mm needs " + std::to_string(n) +
                           " grid points along an axis; allowed: at most 2^19 (choose a larger voxel)");
    steps[a] = std::int64_t(n);
  }
  // Bins list each vessel within one cell of its level (and a step) of the bin: the distance
  // near the surface is exact, its sign everywhere.
  VascularTree inflated = t;
  double area_over_cell2 = 0;
  for (auto s : vessels) {
    const double c = cellSize(coarse[std::size_t(s)]), band = c + h, r = t.maxRadius(s);
    inflated.radius[s] += band;
    if (inflated.radius_start[s] >= 0) inflated.radius_start[s] += band;
    area_over_cell2 += (2 * std::numbers::pi * r * t.length[s] + 4 * std::numbers::pi * r * r) / (c * c);
    // Near a gap: cells of the finest level over a strip where the walls are within a few of
    // them (as wide as a chord of that sagitta), coarser ones around (as many again).
    if (level[std::size_t(s)] < coarse[std::size_t(s)]) {
      const double f = cellSize(level[std::size_t(s)]), strip = 2 * std::sqrt(2 * r * (kGapCells + 1) * f);
      area_over_cell2 += 2 * (t.length[s] + 2 * r) * strip / (f * f);
    }
  }
  lat.grid.spacing_mm = Vec3(h, h, h);
  lat.grid.origin_mm = lat.origin;
  for (int a = 0; a < 3; ++a) lat.grid.dims[a] = std::int32_t(steps[a] + 1);
  // Bins (12 bytes a pair); about 4 octree cells per cell² of vessel surface (64 bytes in the
  // octree's sets); about 8 triangles per cell² (marching tetrahedra) at a peak of about 170
  // bytes each (the units' triangles and vertices until they are welded, and the mesh): an upper
  // bound of the peak (docs/benchmarks.md compares it with the measured one).
  const double estimate = brickPairBound(inflated, lat.grid) * 12 + area_over_cell2 * (4 * 64 + 8 * 170);
  if (report) report->voxel_mm = h, report->coarsest_mm = cellSize(top), report->estimated_bytes = estimate;
  if (o.memory_limit > 0 && estimate > double(o.memory_limit))
    throw InputError("", 0,
                     "the surface at a step of " + std::to_string(h) + " mm needs about " + formatBytes(std::uint64_t(estimate)) +
                         " of memory, more than the limit of " + formatBytes(o.memory_limit) +
                         "; allowed: a larger voxel or a higher --memory-limit");
  lat.bins = binSegments(inflated, lat.grid);
  inflated = VascularTree();
  plan.vessels = std::move(vessels);
  plan.h = h;
  plan.level = std::move(level);
  plan.coarse = std::move(coarse);
  plan.fillet = std::move(fillet);
  plan.top = top;
  plan.lat = std::move(lat);
  return plan;
}

// The cells asked for: at each vessel's level, those its surface may pass through.
std::vector<std::vector<std::uint64_t>> requestedCells(const VascularTree& t, const SurfaceOptions& o, const ContourPlan& plan) {
  const auto& vessels = plan.vessels;
  const auto &level = plan.level, &coarse = plan.coarse;
  const auto& fillet = plan.fillet;
  const int top = plan.top;
  const Lattice& lat = plan.lat;
  const auto cellSize = [&](int l) { return plan.cellSize(l); };
  // Cells asked for: at each vessel's level, those its surface may pass through, found by
  // descending from the top level.
  std::vector<std::vector<std::uint64_t>> requests(std::size_t(top + 1));
  {
    tbb::enumerable_thread_specific<std::vector<std::vector<std::uint64_t>>> local(
        [&] { return std::vector<std::vector<std::uint64_t>>(std::size_t(top + 1)); });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vessels.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
      auto& out = local.local();
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const auto s = vessels[i];
        const int l = level[std::size_t(s)], l_coarse = coarse[std::size_t(s)];
        const Capsule cap = capsuleOf(t, s);
        std::vector<Capsule> partners;
        if (hasGapPartners(o, s))
          for (auto q : o.vessel_gap_partners[std::size_t(s)]) partners.push_back(capsuleOf(t, q));
        // A cell of this vessel at level m is fine enough where it lies at least kGapCells of
        // its size from every partner's surface (only near a gap are cells finer than l_coarse).
        const auto clearOfGaps = [&](const Vec3& centre, double c) {
          for (const auto& p : partners)
            if (p.depth(centre) - 0.8660254037844387 * c < kGapCells * c) return false;
          return true;
        };
        // A cell the surface passes through has its centre within half a diagonal of it (the
        // distance is 1-Lipschitz); the cells around are the balance's and the top cells' job.
        // (The fillet stands off the vessel by at most a quarter of its width.)
        const double margin = 1e-9 * cellSize(l) + fillet[std::size_t(s)] / 4, reach = t.maxRadius(s) + cellSize(l_coarse);
        const Vec3 a = t.position[t.parent[s]], b = t.position[s];
        std::int64_t c0[3], c1[3];
        for (int ax = 0; ax < 3; ++ax) {
          c0[ax] = std::int64_t(std::floor((std::min(a[ax], b[ax]) - reach - lat.origin[ax]) / cellSize(top)));
          c1[ax] = std::int64_t(std::floor((std::max(a[ax], b[ax]) + reach - lat.origin[ax]) / cellSize(top)));
        }
        const std::function<void(int, std::int64_t, std::int64_t, std::int64_t)> descend = [&](int m, std::int64_t x, std::int64_t y,
                                                                                               std::int64_t z) {
          const double c = cellSize(m);
          const Vec3 centre = lat.origin + Vec3((double(x) + 0.5) * c, (double(y) + 0.5) * c, (double(z) + 0.5) * c);
          if (std::abs(cap.depth(centre)) > 0.8660254037844387 * c + margin) return;
          if (m == l || (m <= l_coarse && clearOfGaps(centre, c))) {
            out[std::size_t(m)].push_back(cellCode(x, y, z));
            return;
          }
          for (int k = 0; k < 8; ++k) descend(m - 1, 2 * x + (k & 1), 2 * y + ((k >> 1) & 1), 2 * z + ((k >> 2) & 1));
        };
        for (std::int64_t z = c0[2]; z <= c1[2]; ++z)
          for (std::int64_t y = c0[1]; y <= c1[1]; ++y)
            for (std::int64_t x = c0[0]; x <= c1[0]; ++x) descend(top, x, y, z);
      }
    });
    for (auto& per_thread : local)
      for (int l = 0; l <= top; ++l)
        requests[std::size_t(l)].insert(requests[std::size_t(l)].end(), per_thread[std::size_t(l)].begin(), per_thread[std::size_t(l)].end());
    for (auto& r : requests) {
      std::sort(r.begin(), r.end());
      r.erase(std::unique(r.begin(), r.end()), r.end());
    }
  }
  return requests;
}

// Folds of the dual contour relaxed, then tangles smoothed off the surface: the triangles that
// still cross (none: a surface without self-intersections).
std::vector<std::int32_t> relaxAndUntangle(SurfaceMesh& dual, const Vec3& origin, double h,
                                           const std::function<double(std::int32_t, const Vec3&)>& distance) {
  // Folds relaxed until no two triangles cross (the moved vertices back on the surface).
  std::vector<std::int32_t> tree_of;
  const auto treesOfVertices = [&] {
    tree_of.assign(dual.vertices.size(), 0);
    for (std::size_t k = 0; k < dual.triangles.size(); ++k)
      for (auto v : dual.triangles[k]) tree_of[std::size_t(v)] = dual.triangle_tree[k];
  };
  treesOfVertices();
  std::vector<std::int32_t> crossing;
  // Checked again after a move only where it moved: the triangles at moved vertices and
  // those that crossed are dirty, the other pairs did not cross and stand.
  std::vector<Vec3> before;
  std::vector<char> dirty;
  const auto recheck = [&] {
    dirty.assign(dual.triangles.size(), 0);
    for (auto k : crossing) dirty[std::size_t(k)] = 1;
    for (std::size_t k = 0; k < dual.triangles.size(); ++k)
      for (auto v : dual.triangles[k]) {
        const Vec3 &p = dual.vertices[std::size_t(v)], &q = before[std::size_t(v)];
        if (p.x != q.x || p.y != q.y || p.z != q.z) dirty[k] = 1;
      }
    crossing = crossingTriangles(dual, origin, h, false, &dirty);
  };
  for (int round = 0; round < kRelaxRounds; ++round) {
    if (round > 0) before = dual.vertices;
    relax(dual, tree_of, crossing, distance);
    if (round == 0)
      crossing = crossingTriangles(dual, origin, h);
    else
      recheck();
    if (crossing.empty()) break;
  }
  // Tangles relax cannot undo (sheets a fifth of a step apart at creases and thin gaps):
  // smoothed off the surface, within kUntangleOffset of a step.
  for (int round = 0; round < kUntangleRounds && !crossing.empty(); ++round) {
    if (removeThreeFans(dual, crossing, dirty)) {
      treesOfVertices();
      crossing = crossingTriangles(dual, origin, h, false, &dirty);
      if (crossing.empty()) break;
    }
    before = dual.vertices;
    untangle(dual, tree_of, crossing, round + 1, distance);
    recheck();
  }
  return crossing;
}

// Weld: one vertex per (tree, edge), numbered in key order; triangles in unit order. Units
// that share an edge computed the same vertex, so the first copy stands for all.
void weldUnits(std::vector<UnitMesh>& meshes, SurfaceMesh& mesh, std::vector<Vec3>& along, std::vector<double>& on_edge) {
  struct Copy {
    EdgeKey key;
    std::uint32_t unit, local;
  };
  std::vector<std::size_t> offset(meshes.size() + 1, 0), first_copy(meshes.size() + 1, 0);
  for (std::size_t u = 0; u < meshes.size(); ++u) {
    first_copy[u + 1] = first_copy[u] + meshes[u].vertices.size();
    offset[u + 1] = offset[u] + meshes[u].triangles.size();
  }
  std::vector<Copy> copies(first_copy.back());
  std::vector<std::vector<std::int32_t>> global(meshes.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, meshes.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t u = r.begin(); u != r.end(); ++u) {
      global[u].resize(meshes[u].vertices.size());
      for (std::size_t v = 0; v < meshes[u].vertices.size(); ++v)
        copies[first_copy[u] + v] = {meshes[u].vertices[v].key, std::uint32_t(u), std::uint32_t(v)};
    }
  });
  tbb::parallel_sort(copies.begin(), copies.end(),
                     [](const Copy& a, const Copy& b) { return std::tie(a.key, a.unit, a.local) < std::tie(b.key, b.unit, b.local); });
  // The first copy of each key is the vertex, numbered in key order (by a running count; the
  // rest in parallel: on a part of 20 M triangles this loop was a sixth of its time).
  const auto leads = [&](std::size_t i) { return i == 0 || !(copies[i - 1].key == copies[i].key); };
  std::vector<std::int32_t> id(copies.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, copies.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) id[i] = leads(i) ? 1 : 0;
  });
  std::inclusive_scan(id.begin(), id.end(), id.begin());
  const std::size_t nv = id.empty() ? 0 : std::size_t(id.back());
  mesh.vertices.resize(nv);
  mesh.vertex_step.resize(nv);
  along.assign(nv, Vec3());
  on_edge.assign(nv, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, copies.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const auto& c = copies[i];
      const auto k = std::size_t(id[i] - 1);
      if (leads(i)) {
        const auto& v = meshes[c.unit].vertices[c.local];
        mesh.vertices[k] = v.position;
        mesh.vertex_step[k] = float(norm(v.along));
        along[k] = v.along;
        on_edge[k] = v.t;
      }
      global[c.unit][c.local] = std::int32_t(k);
    }
  });
  std::vector<std::int32_t>().swap(id);
  std::vector<Copy>().swap(copies);
  mesh.triangles.resize(offset.back());
  mesh.triangle_tree.resize(offset.back());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, meshes.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t u = r.begin(); u != r.end(); ++u) {
      for (std::size_t k = 0; k < meshes[u].triangles.size(); ++k) {
        const auto& tri = meshes[u].triangles[k];
        mesh.triangles[offset[u] + k] = {global[u][std::size_t(tri[0])], global[u][std::size_t(tri[1])], global[u][std::size_t(tri[2])]};
        mesh.triangle_tree[offset[u] + k] = meshes[u].triangle_tree[k];
      }
      UnitMesh().vertices.swap(meshes[u].vertices);
    }
  });
}

}  // namespace

SurfaceMesh vesselSurface(const VascularTree& t, const SurfaceOptions& o, SurfaceReport* report,
                          const std::function<void(std::int64_t, std::int64_t)>& progress) {
  ContourPlan plan = planContour(t, o, report);
  SurfaceMesh mesh;
  if (plan.vessels.empty()) return mesh;
  const Lattice& lat = plan.lat;
  const double h = plan.h;
  const int top = plan.top;
  const auto& fillet = plan.fillet;
  std::vector<std::vector<std::uint64_t>> requests = requestedCells(t, o, plan);
  const BalancedOctree octree(top, std::move(requests));
  // Units: the level-3 nodes (8³ finest cells) with their leaves, and the coarser leaves alone.
  const std::vector<OctreeLeaf> units = octree.units(kUnitLevel);
  std::vector<Solid> solids(std::size_t(t.nodeCount()));
  for (auto s : plan.vessels) solids[std::size_t(s)] = {capsuleOf(t, s), fillet[std::size_t(s)]};
  // The solids of a tree in the bin of a point, as the units sample it.
  const auto solidsAt = [&](std::int32_t tree, const Vec3& p) -> const std::vector<Solid>& {
    const Vec3 half = (p - lat.origin) / (0.5 * lat.h);
    thread_local std::vector<Solid> here;
    here.clear();
    if (const auto* segs = lat.segmentsIn(Lattice::binOf(half.x), Lattice::binOf(half.y), Lattice::binOf(half.z)))
      for (auto s : *segs)
        if ((t.tree.empty() ? 0 : t.tree[s]) == tree) here.push_back(solids[std::size_t(s)]);
    return here;
  };
  const std::function<double(std::int32_t, const Vec3&)> distance = [&](std::int32_t tree, const Vec3& p) {
    return unionDistance(solidsAt(tree, p), p);
  };
  const std::function<double(std::int32_t, const Vec3&)> strict = [&](std::int32_t tree, const Vec3& p) {
    return strictDistance(solidsAt(tree, p), p);
  };
  if (o.dual) {
    const char* refused = nullptr;
    if (auto dual = dualContour(t, lat, octree, units, fillet, refused, progress)) {
      if (o.restore_volume) {
        const double moved = restoreVolumeAlongNormals(*dual, distance);
        if (report) report->largest_volume_move_mm = moved;
      }
      auto removed = removeCavities(*dual);
      if (!closedManifold(*dual)) {
        refused = "not a closed manifold";
      } else {
        const std::vector<std::int32_t> crossing = relaxAndUntangle(*dual, lat.origin, h, distance);
        if (!crossing.empty())
          refused = "self-intersecting";
        else
          removed += removeSpecks(*dual);
      }
      if (!refused) {
        if (report)
          report->dual = true, report->cavities_removed = removed, report->cells = std::int64_t(dual->vertices.size()),
          report->units = std::int64_t(units.size()), report->levels = top + 1;
        if (o.finish) o.finish(*dual, strict);
        return std::move(*dual);
      }
    }
    if (report) report->dual_refused = refused;
  }
  std::atomic<std::int64_t> cells{0};
  std::vector<UnitMesh> meshes(units.size());
  forEachUnit(t, lat, octree, units, fillet, progress, [&](UnitMesher& mesher, std::size_t u, const std::vector<OctreeLeaf>& leaves) {
    auto& out = meshes[u];
    cells += std::int64_t(leaves.size());
    mesher.mesh(units[u].level, units[u].cell, leaves.data(), leaves.data() + leaves.size(), out);
    out.vertices.shrink_to_fit();
    out.triangles.shrink_to_fit();
    out.triangle_tree.shrink_to_fit();
  });
  if (report) report->cells = cells, report->units = std::int64_t(units.size()), report->levels = top + 1;
  std::vector<Vec3> along;  // per vertex, its edge
  std::vector<double> on_edge;
  weldUnits(meshes, mesh, along, on_edge);
  if (o.restore_volume) {
    const double moved = restoreVolume(mesh, along, on_edge, distance);
    if (report) report->largest_volume_move_mm = moved;
  }
  const auto removed = removeCavities(mesh);
  if (report) report->cavities_removed = removed;
  if (o.finish) o.finish(mesh, strict);
  return mesh;
}

void keepTriangles(SurfaceMesh& m, const std::vector<char>& keep, std::vector<std::int32_t>* renumber_out) {
  std::vector<std::int32_t> own;
  std::vector<std::int32_t>& renumber = renumber_out ? *renumber_out : own;
  renumber.assign(m.vertices.size(), -1);
  std::size_t nt = 0;
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    if (!keep[k]) continue;
    m.triangles[nt] = m.triangles[k];
    m.triangle_tree[nt] = m.triangle_tree[k];
    if (!m.triangle_face.empty()) m.triangle_face[nt] = m.triangle_face[k];
    for (auto v : m.triangles[nt]) renumber[std::size_t(v)] = 0;
    ++nt;
  }
  m.triangles.resize(nt);
  m.triangle_tree.resize(nt);
  if (!m.triangle_face.empty()) m.triangle_face.resize(nt);
  std::size_t nv = 0;
  for (std::size_t v = 0; v < renumber.size(); ++v) {
    if (renumber[v] < 0) continue;
    renumber[v] = std::int32_t(nv);
    m.vertices[nv] = m.vertices[v];
    if (!m.vertex_step.empty()) m.vertex_step[nv] = m.vertex_step[v];
    ++nv;
  }
  m.vertices.resize(nv);
  if (!m.vertex_step.empty()) m.vertex_step.resize(nv);
  for (auto& t : m.triangles)
    for (auto& v : t) v = renumber[std::size_t(v)];
}

MeshTopology meshTopology(const SurfaceMesh& m) {
  MeshTopology out;
  // Directed edges (from, to) bucketed by their lower vertex (a counting sort, linear): a
  // closed, consistently oriented surface uses every edge once in each direction.
  const std::size_t nv = m.vertices.size();
  std::vector<std::uint32_t> first(nv + 1, 0);
  double six_v = 0;
  for (const auto& tri : m.triangles) {
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) ++out.degenerate_triangles;
    for (int e = 0; e < 3; ++e) ++first[std::size_t(std::min(tri[e], tri[(e + 1) % 3])) + 1];
    six_v += dot(m.vertices[tri[0]], cross(m.vertices[tri[1]], m.vertices[tri[2]]));
  }
  out.volume_mm3 = six_v / 6;
  for (std::size_t v = 0; v < nv; ++v) first[v + 1] += first[v];
  std::vector<std::int64_t> uses(first[nv]);  // the upper vertex × 2 + (forward)
  {
    std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
    for (const auto& tri : m.triangles)
      for (int e = 0; e < 3; ++e) {
        const std::int64_t a = tri[e], b = tri[(e + 1) % 3];
        uses[fill[std::size_t(std::min(a, b))]++] = std::max(a, b) * 2 + (a < b);
      }
  }
  std::int32_t trees = 0;
  for (auto tree : m.triangle_tree) trees = std::max(trees, tree + 1);
  out.tree_components.assign(std::size_t(trees), 0);
  out.tree_euler.assign(std::size_t(trees), 0);
  std::vector<std::int32_t> tree_of(nv, -1);
  for (std::size_t k = 0; k < m.triangles.size(); ++k) {
    out.tree_euler[std::size_t(m.triangle_tree[k])] += 1;  // F
    for (auto v : m.triangles[k]) tree_of[std::size_t(v)] = m.triangle_tree[k];
  }
  for (std::size_t v = 0; v < nv; ++v) {
    const auto b = uses.begin() + first[v], e = uses.begin() + first[v + 1];
    std::sort(b, e);
    for (auto i = b; i != e;) {
      auto j = i;
      while (j != e && (*j >> 1) == (*i >> 1)) ++j;
      if (j - i == 1)
        ++out.boundary_edges;
      else if (j - i > 2)
        ++out.nonmanifold_edges;
      else if ((*i & 1) == (*(i + 1) & 1))
        ++out.misoriented_edges;
      out.tree_euler[std::size_t(tree_of[v])] -= 1;  // E
      i = j;
    }
  }
  // Components (union-find over shared vertices) and V, per tree.
  const auto component = componentOf(m);
  for (std::size_t v = 0; v < nv; ++v) {
    if (tree_of[v] < 0) continue;
    out.tree_euler[std::size_t(tree_of[v])] += 1;  // V
    out.tree_components[std::size_t(tree_of[v])] += component[v] == std::int32_t(v);
  }
  return out;
}

}  // namespace angiosynth
