#include "mesh/tube_surface.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <numbers>
#include <tuple>
#include <unordered_map>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "core/union_find.hpp"
#include "core/segment_index.hpp"
#include "mesh/decimate.hpp"
#include "mesh/net_surface.hpp"
#include "mesh/ring_mesh.hpp"
#include "raster/vessel_capsule.hpp"

namespace angiosynth {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
// Vessels whose axes come closer than this many times the sum of their radii touch.
constexpr double kTouching = 1.1;
// A part with a handle it should not have is contoured again at most this many times, finer.
constexpr int kRefinements = 2;
// Gaps are not resolved in parts of more vessels (a gap's step multiplies their grid).
constexpr std::size_t kLargestGapPart = 64;
// A tube is at least this many radii long.
constexpr double kShortestTube = 0.25;
// A stub is prolonged this many radii past its cut (vessel_ends' overshoot), and ends there in a
// round tip of its radius.
constexpr double kStubOvershoot = 1;
// A tube's first ring from a contoured loop stands this many radii from it (or a third of the tube).
constexpr double kLoopBand = 0.5;
// A failed cut is tried again this many times, each this many radii further into its tube (or
// what the tube has left, at least kLeastCutShift).
constexpr int kCutRetries = 2;
constexpr double kCutShift = 0.5, kLeastCutShift = 0.02;
// A failed cut made again in the same contour moves this far: within its overshoot (a radius).
constexpr double kRecutShift = 0.5;
// Two vessels of a tree that come close without touching are contoured together, with cells of
// a third of their gap (the fillet then stays in the gap and no tetrahedron spans it) along the
// stretch of each where its wall comes within two of its own cells of the other's, unless that
// is more than this many times finer than their own cells: then they count as touching.
constexpr double kFinestGapCells = 16;  // (kGapCells: vessel_surface.hpp)
// Parts of more vessels than this are large: meshed on a task of their own.
constexpr std::size_t kLargePart = 256;

// A vessel as the mesher sees it: its two junction nodes (links merged), its axis and radii, and
// where its tube starts and ends.
struct Vessel {
  std::int32_t s = -1, tree = 0;
  std::int32_t node[2] = {-1, -1};  // junction nodes at its proximal (0) and distal (1) end
  Vec3 a, b, u;                     // ends and unit axis a → b, mm
  double len = 0, ra = 0, rb = 0;
  double sin_a = 0, cos_a = 1;  // a round cone's side slope
  bool nested = false;          // a cone with no side (one sphere holds the other)
  // Distances of the tube's ends from a (side 0) and from b (side 1) along the axis: a cut's
  // plane, or a CFD end's plane beyond the node (negative).
  double plane[2] = {0, 0};
  int end[2] = {-1, -1};           // the CFD end (options.ends index) at each side, or -1
  bool round[2] = {false, false};  // a round end of the tree (no other vessel at that node)
  bool tube = false;
  bool looped = false;  // its tube runs from a contoured part back to the same part

  double rmax() const { return std::max(ra, rb); }
  // How far side k's CFD end prolongs the axis beyond its node (0 without one), and the distance
  // from a of the point at parameter s of the prolonged axis.
  double prolonged(int k) const { return std::max(0.0, -plane[k]); }
  double fromAOnAxis(double s) const { return s * (len + prolonged(0) + prolonged(1)) - prolonged(0); }
  // The wall's distance from the axis at distance y from a along it (a CFD prolongation beyond
  // an end is a cylinder of that end's radius).
  double radiusAt(double y) const {
    if (ra == rb) return ra;
    if (y <= 0) return ra;
    if (y >= len) return rb;
    return (ra - y * sin_a) / cos_a;
  }
  // Side k's node, its direction into the vessel, and the distance along that direction from
  // the node to the point at distance y from a.
  Vec3 nodeAt(int k) const { return k == 0 ? a : b; }
  Vec3 into(int k) const { return k == 0 ? u : u * -1.0; }
  double fromA(int k, double d) const { return k == 0 ? d : len - d; }
};

// The contour step near a vessel of radius r (vesselLevels: cells of 2r / samples_across).
double stepNear(double r, const SurfaceOptions& o) { return 2 * r / std::max(1, o.samples_across); }

// Where side k's cut must lie so that no other vessel at its node enters the region the cut
// reads (endCutExtent: behind the plane, past it, around the axis): a vessel o leaving the node
// at angle θ to this one has its points within r_o of its axis, so along this axis it reaches
// r_o where it turns away (θ ≥ 90°), else d·cos θ + r_o up to the distance d where its axis is
// reach + r_o from this one's.
// The region is read with the stub's own step.
double cutDistance(const Vessel& v, int k, const std::vector<const Vessel*>& others, const SurfaceOptions& o) {
  const double r = v.rmax();
  const Vec3 w = v.into(k);
  double plane = endCutExtent(r, stepNear(r, o), true).before;
  for (const Vessel* q : others) {
    if (q == &v) continue;
    const int kq = q->node[0] == v.node[k] ? 0 : 1;
    const double c = dot(w, q->into(kq)), ro = q->rmax();
    const auto x = endCutExtent(r, stepNear(r, o), true);
    double axial = ro;
    if (c > 0) {
      const double sin_t = std::sqrt(std::max(0.0, 1 - c * c));
      const double d = sin_t > 1e-12 ? std::min(q->len, (x.reach + ro) / sin_t) : q->len;
      axial = d * c + ro;
    }
    plane = std::max(plane, axial + x.before);
  }
  return plane;
}

// A tube's end as a cluster cuts it.
struct Stub {
  std::int32_t vessel;  // index into the vessels
  int side;
};

// Two vessels of a tree, sharing no node, whose axes come closer than kTouching times their
// radii: the cell that resolves the gap between their walls, or 0 where they touch.
struct ClosePair {
  std::int32_t i, j;
  double gap_cell;
  double span_i[2], span_j[2];  // the close stretches, distances from each vessel's a
  bool touching = true;         // else apart across a gap, or joined only through the vessel `via`
  bool overlapping = false;     // their walls overlap (through `via`)
  std::int32_t via = -1;
  // Through `via`: the sides of i and j at its nodes, and how far from those nodes their cuts
  // must lie so that their tubes run clear of each other (the stretch where they come close is
  // contoured with the connector).
  int side_i = 0, side_j = 0;
  double past_i = 0, past_j = 0;
};

// Where a part's vessel needs fine cells: from y0 to y1 (distances from its a), cells no larger than `cell`.
struct GapSpan {
  std::int32_t vessel;
  double cell, y0, y1;
  std::vector<std::int32_t> partners;  // the vessels across the gap: the fine cells stay near them
};

struct Cluster {
  std::int32_t tree = 0;
  std::vector<std::int32_t> whole;  // vessels contoured whole
  std::vector<Stub> stubs;          // tubes cut at this cluster's side
  bool touching = false;            // holds vessels that touch without sharing a node (its union may have handles)
  std::int32_t parts = 1;           // components of its union (vessels close across a gap stay apart)
  // Where vessels touch without overlapping (walls a hair apart), a contour may close the gap or
  // not: its union then has from `parts` to `parts_apart` components, each contact that closes
  // joining two of them or making a handle.
  std::int32_t parts_apart = 1, contacts = 0;
  std::vector<GapSpan> gap_spans;  // whole vessels that need finer cells along a stretch
};

// What a cluster gives: its surface (its own vertex numbering) and each stub's loop, counter-
// clockwise around the vessel's axis a → b, or empty if its cut failed.
struct ClusterMesh {
  SurfaceMesh mesh;
  std::vector<std::vector<std::int32_t>> loops;
  std::vector<std::int32_t> end_ids;  // CFD ends cut here (options.ends indices)
  EndCutReport ends;                  // for those, in that order
  double estimated_bytes = 0, step = 0;
  std::int64_t cavities_removed = 0;
  DecimateReport decimation, slivers, remeshing;
  std::int64_t contoured = 0;  // triangles contoured, with those cut away and contours made again
  int refinements = 0;         // contoured again, finer, to lose a handle
  std::vector<double> planes;  // each stub's cut distance from its node, as made
  int cut_retries = 0;         // contoured again with cuts further into their tubes
  bool netted = false;         // by surface nets (net_surface.hpp), else marching tetrahedra
};

class TubeMesher {
 public:
  TubeMesher(const VascularTree& t, const TubeSurfaceOptions& o) : t_(t), o_(o) {}

  SurfaceMesh run(TubeSurfaceReport& rep, const std::function<void(std::int64_t, std::int64_t)>& progress) {
    collectVessels();
    rep.vessels = std::int64_t(vessels_.size());
    if (vessels_.empty()) return {};
    refuseTubesBeyondLimit();
    placeCuts();
    findClosePairs();  // from the geometry alone: the same every round
    std::vector<char> give_up(vessels_.size(), 0);
    std::vector<ClusterMesh> meshes;
    std::vector<Cluster> clusters;
    // Each round gives up at least one more tube, so it ends (at worst with every vessel whole).
    for (;;) {
      decideTubes(give_up);
      std::vector<Cluster> next = buildClusters();
      // A part the last round meshed already (same vessels, same cuts) is kept.
      std::map<std::vector<std::int64_t>, std::size_t> before;
      for (std::size_t c = 0; c < clusters.size(); ++c) before.emplace(keyOf(clusters[c]), c);
      std::vector<ClusterMesh> next_meshes(next.size());
      std::vector<std::size_t> todo;
      for (std::size_t c = 0; c < next.size(); ++c) {
        const auto it = before.find(keyOf(next[c]));
        if (it != before.end())
          next_meshes[c] = std::move(meshes[it->second]);
        else
          todo.push_back(c);
      }
      clusters = std::move(next);
      meshes = std::move(next_meshes);
      const std::int64_t total = std::int64_t(todo.size());
      ++rep.rounds;
      for (auto c : todo) rep.largest_remeshed = std::max<std::int64_t>(rep.largest_remeshed, std::int64_t(clusters[c].whole.size()));
      // A large part (the 100k tree's largest holds 13 k vessels) starts first, on its own task:
      // its serial steps (welding, cutting its stubs) then overlap the small parts' work instead
      // of holding a batch of them. The small parts go in batches, so progress is reported from
      // this thread.
      std::vector<std::size_t> small;
      tbb::task_group large;
      std::atomic<std::int64_t> large_done{0};
      for (auto c : todo) {
        if (clusters[c].whole.size() + clusters[c].stubs.size() <= kLargePart) {
          small.push_back(c);
          continue;
        }
        large.run([&, c] {
          meshes[c] = meshCluster(clusters[c]);
          ++large_done;
        });
      }
      for (std::size_t first = 0; first < small.size(); first += 1024) {
        const std::size_t last = std::min(small.size(), first + 1024);
        tbb::parallel_for(first, last, [&](std::size_t i) { meshes[small[i]] = meshCluster(clusters[small[i]]); });
        if (progress) progress(std::int64_t(last) + large_done, total);
      }
      large.wait();
      if (progress) progress(total, total);
      // Where each part cut its tubes (a retried cut lies further in), for the tubes' rings.
      for (auto c : todo)
        for (std::size_t k = 0; k < clusters[c].stubs.size(); ++k)
          vessels_[std::size_t(clusters[c].stubs[k].vessel)].plane[clusters[c].stubs[k].side] = meshes[c].planes[k];
      // A cut that failed still gives its tube up: the vessel is contoured whole, with its neighbours.
      bool again = false;
      for (auto c : todo)
        for (std::size_t k = 0; k < clusters[c].stubs.size(); ++k)
          if (meshes[c].loops[k].empty()) give_up[std::size_t(clusters[c].stubs[k].vessel)] = 1, again = true, ++rep.fallbacks;
      if (!again) break;
    }
    return assemble(clusters, meshes, rep);
  }

 private:
  std::int32_t treeOf(std::int32_t s) const { return t_.tree.empty() ? 0 : t_.tree[s]; }

  // Vertices of a vessel's rings.
  int ringVertices(const Vessel& v) const {
    int n = o_.ring_vertices > 0 ? o_.ring_vertices
                                 : std::max(o_.min_ring_vertices, int(std::ceil(std::numbers::pi * std::max(1, o_.junction.samples_across))));
    // A chord of a ring of n stands r (1 − cos π/n) inside the wall at its middle.
    if (o_.ring_tolerance_mm > 0 && o_.ring_tolerance_mm < v.rmax())
      n = std::max(n, int(std::ceil(std::numbers::pi / std::acos(1 - o_.ring_tolerance_mm / v.rmax()))));
    return n;
  }

  // Every vessel as one tube, before anything is meshed: an upper bound of the tubes' triangles
  // (the contoured parts take some vessels, and have an estimate of their own). A kilometre of a
  // thin vessel is a million rings.
  void refuseTubesBeyondLimit() const {
    if (o_.junction.memory_limit == 0) return;
    constexpr double kBytesPerTriangle = 64;  // the mesh's arrays, their copies while parts are joined, the writer's
    double triangles = 0;
    for (const auto& v : vessels_) {
      const int n = ringVertices(v);
      const double spacing = (o_.ring_spacing_radii > 0 ? o_.ring_spacing_radii : kCfdRingSpacing * kTwoPi / n) * 0.5 * (v.ra + v.rb);
      triangles += 2.0 * n * (std::ceil(v.len / spacing) + 4);
    }
    const double bytes = triangles * kBytesPerTriangle;
    if (bytes > double(o_.junction.memory_limit))
      throw InputError("", 0,
                       "the vessels' tubes make about " + std::to_string(std::llround(triangles)) + " triangles, which need about " +
                           formatBytes(std::uint64_t(bytes)) + " of memory, more than the limit of " + formatBytes(o_.junction.memory_limit) +
                           "; allowed: rings further apart (--ring-spacing), fewer --samples-across, or a larger --memory-limit");
  }

  void collectVessels() {
    for (std::int32_t s = 0; s < t_.nodeCount(); ++s) {
      if (t_.isRoot(s) || t_.isLink(s)) continue;
      Vessel v;
      v.s = s;
      v.tree = treeOf(s);
      v.node[0] = t_.junction(t_.parent[s]);
      v.node[1] = s;
      v.a = t_.position[t_.parent[s]];
      v.b = t_.position[s];
      v.len = distance(v.a, v.b);
      v.u = v.len > 0 ? (v.b - v.a) / v.len : Vec3(1, 0, 0);
      v.ra = t_.startRadius(s);
      v.rb = t_.radius[s];
      if (!(v.ra > 0 && v.rb > 0)) throw InputError("", 0, "a vessel of radius 0 has no surface; every radius must be > 0");
      if (v.ra != v.rb) {
        v.nested = std::abs(v.ra - v.rb) >= v.len;
        if (!v.nested) {
          v.sin_a = (v.ra - v.rb) / v.len;
          v.cos_a = std::sqrt(1 - v.sin_a * v.sin_a);
        }
      }
      vessels_.push_back(v);
    }
    // In an order of the geometry alone (as openEnds), so a tree read back from its graph files,
    // numbered otherwise, gives the same mesh.
    std::sort(vessels_.begin(), vessels_.end(), [](const Vessel& x, const Vessel& y) {
      return std::make_tuple(x.tree, x.a.x, x.a.y, x.a.z, x.b.x, x.b.y, x.b.z) < std::make_tuple(y.tree, y.a.x, y.a.y, y.a.z, y.b.x, y.b.y, y.b.z);
    });
    for (std::size_t i = 0; i < vessels_.size(); ++i) index_of_[vessels_[i].s] = std::int32_t(i);
    at_node_.assign(std::size_t(t_.nodeCount()), {});
    for (auto& v : vessels_)
      for (int k = 0; k < 2; ++k) at_node_[std::size_t(v.node[k])].push_back(&v);
    for (std::size_t e = 0; e < o_.ends.size(); ++e) {
      const auto& end = o_.ends[e];
      const auto it = index_of_.find(end.vessel);
      if (it == index_of_.end()) continue;
      vessels_[std::size_t(it->second)].end[end.root ? 0 : 1] = int(e);
    }
  }

  // Each side's plane: a CFD end's (beyond its node), else past the other vessels at the node.
  void placeCuts() {
    for (auto& v : vessels_)
      for (int k = 0; k < 2; ++k) {
        if (v.end[k] >= 0) {
          const auto& e = o_.ends[std::size_t(v.end[k])];
          v.plane[k] = -dot(e.centre - e.node, e.normal);
        } else if (at_node_[std::size_t(v.node[k])].size() == 1) {
          v.round[k] = true;  // the tube runs to the node and ends in a cap of rings
          v.plane[k] = 0;
        } else {
          v.plane[k] = cutDistance(v, k, at_node_[std::size_t(v.node[k])], o_.junction);
        }
      }
  }

  // A vessel keeps a tube when its free middle has some length and no
  // vessel of its tree that shares no node with it touches it (else the two are contoured
  // together, so the surface is their union). Separate surfaces must not cross either: vessels
  // closer than a tenth of their radii count as touching (rings and contours stand off the exact
  // wall by a few hundredths of a radius).
  void decideTubes(const std::vector<char>& give_up) {
    // Two vessels that come close only through a connector keep their tubes, cut past the
    // stretch where they are near each other: that stretch is contoured with the connector, in
    // the part of its two nodes (the cuts only move away from their nodes: the same every round).
    // (Not where a CFD end lies at those nodes: its plane is the end's.)
    const auto cutPastEachOther = [&](const ClosePair& p) {
      return p.via >= 0 && vessels_[std::size_t(p.i)].end[p.side_i] < 0 && vessels_[std::size_t(p.j)].end[p.side_j] < 0;
    };
    for (const auto& p : close_pairs_) {
      if (!cutPastEachOther(p)) continue;
      auto& pi = vessels_[std::size_t(p.i)].plane[p.side_i];
      auto& pj = vessels_[std::size_t(p.j)].plane[p.side_j];
      pi = std::max(pi, p.past_i), pj = std::max(pj, p.past_j);
    }
    for (std::size_t i = 0; i < vessels_.size(); ++i) {
      auto& v = vessels_[i];
      // The two cuts belong to different contoured parts, so their regions may overlap; the
      // tube between them needs only some length.
      const double free_length = v.len - v.plane[0] - v.plane[1];
      v.tube = !give_up[i] && !v.nested && free_length >= kShortestTube * v.rmax();
    }
    for (const auto& p : close_pairs_) {
      if (p.via >= 0) vessels_[std::size_t(p.via)].tube = false;  // the connector joins the two cuts' nodes into one part
      if (!cutPastEachOther(p)) vessels_[std::size_t(p.i)].tube = vessels_[std::size_t(p.j)].tube = false;
    }
    // Unless both its ends lie in one part: there each cut would find the other stub's wall in
    // the region it reads past its plane (its prolongation and round tip reach towards it), and
    // fail however far it moves, so a tube too short to keep the two apart is contoured whole
    // with that part (which it joins to nothing new: the parts stay as they are).
    UnionFind parts = partNodes();
    for (auto& v : vessels_) {
      v.looped = v.tube && parts.find(v.node[0]) == parts.find(v.node[1]);
      if (v.looped && v.len - v.plane[0] - v.plane[1] < loopedTubeLength(v)) v.tube = false;
    }
  }
  // The free length a looped tube needs: each cut's region past its plane clear of the other
  // stub, which reaches its overshoot and tip past its own plane.
  double loopedTubeLength(const Vessel& v) const {
    const double r = v.rmax();
    return endCutExtent(r, stepNear(r, o_.junction), true).beyond + (kStubOvershoot + 1) * r;
  }
  // Nodes joined into one contoured part: by vessels without a tube and by close pairs (through
  // a connector: the nodes at its ends, where the two are cut); `apart` (if given): only by the
  // vessels and the pairs that overlap (the components of the part's union, its contacts open).
  UnionFind partNodes(UnionFind* apart = nullptr) const {
    UnionFind g(std::size_t(t_.nodeCount()));
    for (const auto& v : vessels_)
      if (!v.tube) {
        g.unite(v.node[0], v.node[1]);
        if (apart) apart->unite(v.node[0], v.node[1]);
      }
    for (const auto& pr : close_pairs_) {
      const auto ni = vessels_[std::size_t(pr.i)].node[pr.side_i], nj = vessels_[std::size_t(pr.j)].node[pr.side_j];
      g.unite(ni, nj);
      if (apart && pr.overlapping) apart->unite(ni, nj);
    }
    return g;
  }
  // Pairs of vessels of a tree that share no node and come close (close_pairs_).
  void findClosePairs() {
    SegmentIndex index(boxLo(), boxHi());
    VascularTree axes;  // one segment per vessel, its CFD prolongations included
    for (const auto& v : vessels_) {
      const Vec3 a = v.a - v.u * v.prolonged(0), b = v.b + v.u * v.prolonged(1);
      const auto root = axes.addNode(a, -1, v.tree);
      axes.addNode(b, root);
    }
    index.refresh(axes, true);
    std::vector<double> reach(vessels_.size());
    for (std::size_t i = 0; i < vessels_.size(); ++i) reach[i] = kTouching * vessels_[i].rmax();
    tbb::enumerable_thread_specific<SegmentIndex::Marks> marks;
    std::vector<std::vector<ClosePair>> found(vessels_.size());
    tbb::parallel_for(std::size_t(0), vessels_.size(), [&](std::size_t i) {
      const auto& v = vessels_[i];
      const std::int32_t seg = 2 * std::int32_t(i) + 1;
      const Vec3 &p0 = axes.position[std::size_t(seg) - 1], &p1 = axes.position[std::size_t(seg)];
      index.forEachNearSegment(p0, p1, 2 * reach[i], marks.local(), [&](std::int32_t y) {
        const std::size_t j = std::size_t(y - 1) / 2;
        if (j == i || !(reach[j] < reach[i] || (reach[j] == reach[i] && j > i))) return;
        const auto& w = vessels_[j];
        if (w.tree != v.tree || w.node[0] == v.node[0] || w.node[0] == v.node[1] || w.node[1] == v.node[0] || w.node[1] == v.node[1]) return;
        const Vec3 &q0 = axes.position[std::size_t(y) - 1], &q1 = axes.position[std::size_t(y)];
        double si = 0, sj = 0;
        const double d = segmentSegmentDistance(p0, p1, q0, q1, si, sj);
        if (!(d < reach[i] + reach[j])) return;
        const Vec3 pi = p0 + (p1 - p0) * si, pj = q0 + (q1 - q0) * sj;
        // The walls' gap where the axes are closest (the nearest points of tapered walls lie a
        // little aside: second order in their slopes). Two vessels that overlap touch, even
        // through a connector: the union may have a handle there.
        const double gap = d - v.radiusAt(v.fromAOnAxis(si)) - w.radiusAt(w.fromAOnAxis(sj));
        const double cell = gap / kGapCells, own = stepNear(std::min({v.ra, v.rb, w.ra, w.rb}), o_.junction);
        ClosePair pr{std::int32_t(i), std::int32_t(j), 0.0, {0, 0}, {0, 0}, true};
        pr.overlapping = !(gap > 0);
        if (const Vessel* m = throughConnector(v, w, pi, pj, gap > 0, pr.side_i, pr.side_j)) {
          pr.touching = false, pr.via = std::int32_t(m - vessels_.data());
          pr.past_i = cutPast(v, pr.side_i, p0, p1, w, q0, q1);
          pr.past_j = cutPast(w, pr.side_j, q0, q1, v, p0, p1);
        } else if (cell * kFinestGapCells >= own)
          pr.gap_cell = cell, pr.touching = false;
        if (pr.gap_cell > 0) {
          const double within = v.rmax() + w.rmax() + 2 * own;
          closeSpan(v, p0, p1, si, q0, q1, within, pr.span_i);
          closeSpan(w, q0, q1, sj, p0, p1, within, pr.span_j);
        }
        found[i].push_back(pr);
      });
    });
    close_pairs_.clear();
    for (const auto& f : found) close_pairs_.insert(close_pairs_.end(), f.begin(), f.end());
  }
  // How far from its side-k node vessel v (axis p0 → p1) must be cut so that the region its
  // cut reads (endCutExtent) holds no point of w (axis q0 → q1): past the stretch of v's axis
  // within reach + r_w of w's axis, by r_w and the region's depth behind the plane.
  double cutPast(const Vessel& v, int k, const Vec3& p0, const Vec3& p1, const Vessel& w, const Vec3& q0, const Vec3& q1) const {
    const auto x = endCutExtent(v.rmax(), stepNear(v.rmax(), o_.junction), true);
    const double within = x.reach + w.rmax();
    double span[2];
    double s = 0, t = 0;
    segmentSegmentDistance(p0, p1, q0, q1, s, t);
    closeSpan(v, p0, p1, s, q0, q1, within, span);
    const double far = k == 0 ? span[1] : v.len - span[0];  // from the node, along the axis into the vessel
    return far + w.rmax() + x.before;
  }
  // The vessel m joining a node of v to one of w if v and w meet only through it, so that the
  // three have a union without a hole (else null): apart, where they come closest within m's
  // radius of the nodes it shares with them (the space between them is m's, not a gap);
  // overlapping, where the three solids share a point (convex solids that pairwise meet and
  // share a point have a union without a hole). The three are contoured together, as a part
  // that must keep no handle.
  // `side_v`, `side_w`: the sides of v and w at the connector's nodes.
  const Vessel* throughConnector(const Vessel& v, const Vessel& w, const Vec3& pi, const Vec3& pj, bool apart, int& side_v, int& side_w) const {
    for (int x = 0; x < 2; ++x)
      for (const Vessel* m : at_node_[std::size_t(v.node[x])]) {
        const int other = m->node[0] == v.node[x] ? 1 : 0;
        for (int y = 0; y < 2; ++y) {
          if (m->node[other] != w.node[y]) continue;
          const auto found = [&] {
            side_v = x, side_w = y;
            return m;
          };
          if (apart) {
            if (distance(pi, v.nodeAt(x)) <= m->rmax() && distance(pj, w.nodeAt(y)) <= m->rmax()) return found();
            continue;
          }
          // The deepest point of the three along lines between their nearest points and the
          // shared nodes: the largest of three convex distances is convex along a line.
          const Capsule cv = capsuleOf(t_, v.s), cw = capsuleOf(t_, w.s), cm = capsuleOf(t_, m->s);
          const auto outside = [&](const Vec3& p) { return std::max({cv.depth(p), cw.depth(p), cm.depth(p)}); };
          const Vec3 nv = v.nodeAt(x), nw = w.nodeAt(y);
          for (const auto& line : {std::pair{pi, pj}, std::pair{nv, pj}, std::pair{pi, nw}, std::pair{nv, nw}}) {
            const Vec3 p0 = line.first, p1 = line.second;  // (Clang 14 captures no structured binding)
            const auto at = [&](double s) { return p0 + (p1 - p0) * s; };
            double lo = 0, hi = 1;
            for (int k = 0; k < 40; ++k) {
              const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
              if (outside(at(m1)) < outside(at(m2)))
                hi = m2;
              else
                lo = m1;
            }
            if (outside(at(0.5 * (lo + hi))) < 0) return found();
          }
        }
      }
    return nullptr;
  }
  // The stretch of vessel v (axis p0 → p1, prolonged) whose points lie within `within` of the
  // axis q0 → q1, around parameter s where it comes closest: the distance is convex along the
  // axis, so each side is a bisection. As distances from the vessel's a, within its length.
  static void closeSpan(const Vessel& v, const Vec3& p0, const Vec3& p1, double s, const Vec3& q0, const Vec3& q1, double within, double span[2]) {
    const auto near = [&](double x) { return pointSegmentDistance(p0 + (p1 - p0) * x, q0, q1) < within; };
    const auto edge = [&](double in, double out) {
      if (near(out)) return out;
      for (int k = 0; k < 50; ++k) {
        const double mid = 0.5 * (in + out);
        (near(mid) ? in : out) = mid;
      }
      return out;
    };
    span[0] = std::clamp(v.fromAOnAxis(edge(s, 0.0)), 0.0, v.len);
    span[1] = std::clamp(v.fromAOnAxis(edge(s, 1.0)), 0.0, v.len);
  }
  Vec3 boxLo() const {
    Vec3 lo(INFINITY, INFINITY, INFINITY);
    for (const auto& v : vessels_)
      lo = componentMin(lo, componentMin(v.a, v.b) - Vec3(1, 1, 1) * (v.rmax() + std::max(v.prolonged(0), v.prolonged(1))));
    return lo;
  }
  Vec3 boxHi() const {
    Vec3 hi(-INFINITY, -INFINITY, -INFINITY);
    for (const auto& v : vessels_)
      hi = componentMax(hi, componentMax(v.a, v.b) + Vec3(1, 1, 1) * (v.rmax() + std::max(v.prolonged(0), v.prolonged(1))));
    return hi;
  }

  // Clusters: nodes joined by vessels without a tube and by close pairs; in the order of their
  // smallest node, so the mesh does not depend on the thread count. A part's union has as many
  // components as its nodes have when its vessels, its overlapping pairs and the contacts it
  // closes join them (parts … parts_apart).
  std::vector<Cluster> buildClusters() {
    UnionFind apart(std::size_t(t_.nodeCount()));
    UnionFind g = partNodes(&apart);
    std::vector<char> touching_root(std::size_t(t_.nodeCount()), 0);
    for (const auto& pr : close_pairs_)
      if (pr.touching) touching_root[std::size_t(g.find(vessels_[std::size_t(pr.i)].node[0]))] = 1;
    std::vector<std::int32_t> slot(std::size_t(t_.nodeCount()), -1);
    std::vector<Cluster> out;
    const auto clusterOf = [&](std::int32_t node, std::int32_t tree) -> Cluster& {
      const auto r = g.find(node);
      if (slot[std::size_t(r)] < 0) {
        slot[std::size_t(r)] = std::int32_t(out.size());
        out.emplace_back();
        out.back().tree = tree;
        out.back().touching = touching_root[std::size_t(r)];
      }
      return out[std::size_t(slot[std::size_t(r)])];
    };
    // Numbered as vessels (in node order) first reach them: the same on any thread count.
    for (std::size_t i = 0; i < vessels_.size(); ++i) {
      const auto& v = vessels_[i];
      if (!v.tube) {
        clusterOf(v.node[0], v.tree).whole.push_back(std::int32_t(i));
        continue;
      }
      for (int k = 0; k < 2; ++k)
        if (v.end[k] < 0 && !v.round[k]) clusterOf(v.node[k], v.tree).stubs.push_back({std::int32_t(i), k});
    }
    for (const auto& pr : close_pairs_) {
      if (!(pr.gap_cell > 0)) continue;
      auto& gs = clusterOf(vessels_[std::size_t(pr.i)].node[0], vessels_[std::size_t(pr.i)].tree).gap_spans;
      gs.push_back({pr.i, pr.gap_cell, pr.span_i[0], pr.span_i[1], {pr.j}});
      gs.push_back({pr.j, pr.gap_cell, pr.span_j[0], pr.span_j[1], {pr.i}});
    }
    // Components of each part's union: joined by its vessels and the pairs that overlap, and by
    // its contacts (pairs that touch without overlapping; in a large part the gaps too) or not.
    for (auto& c : out)
      if (c.whole.size() > kLargestGapPart && !c.gap_spans.empty()) {
        // A large part's grid at a gap's step costs more than its handle: its close pairs touch.
        c.gap_spans.clear();
        c.touching = true;
      }
    std::vector<std::vector<std::pair<std::int32_t, std::int32_t>>> contacts(out.size());
    for (const auto& pr : close_pairs_) {
      const auto ni = vessels_[std::size_t(pr.i)].node[pr.side_i], nj = vessels_[std::size_t(pr.j)].node[pr.side_j];
      const auto c = slot[std::size_t(g.find(ni))];
      if (c < 0 || pr.overlapping || pr.via >= 0 || (!pr.touching && !out[std::size_t(c)].touching)) continue;
      contacts[std::size_t(c)].emplace_back(apart.find(ni), apart.find(nj));
    }
    for (std::size_t k = 0; k < out.size(); ++k) {
      auto& c = out[k];
      std::vector<std::int32_t> roots;
      for (auto i : c.whole)
        for (auto n : vessels_[std::size_t(i)].node) roots.push_back(apart.find(n));
      for (const auto& st : c.stubs) roots.push_back(apart.find(vessels_[std::size_t(st.vessel)].node[st.side]));
      std::sort(roots.begin(), roots.end());
      roots.erase(std::unique(roots.begin(), roots.end()), roots.end());
      c.parts_apart = std::int32_t(roots.size());
      c.contacts = std::int32_t(contacts[k].size());
      UnionFind local(roots.size());
      const auto at = [&](std::int32_t r) { return std::int32_t(std::lower_bound(roots.begin(), roots.end(), r) - roots.begin()); };
      c.parts = c.parts_apart;
      for (const auto& [a, b] : contacts[k])
        if (local.find(at(a)) != local.find(at(b))) local.unite(at(a), at(b)), --c.parts;
    }
    return out;
  }

  // What a part is made of: its whole vessels, then its stubs (vessel, side), as one list.
  static std::vector<std::int64_t> keyOf(const Cluster& c) {
    std::vector<std::int64_t> key(c.whole.begin(), c.whole.end());
    key.push_back(-1);
    for (const auto& st : c.stubs) key.push_back(2 * std::int64_t(st.vessel) + st.side);
    return key;
  }

  // A stub's cut as an end: its plane across the tube at the cut distance from its node.
  VesselEnd stubPlane(const Vessel& v, int k, double plane) const {
    VesselEnd e;
    e.tree = v.tree;
    e.vessel = v.s;
    e.node = v.nodeAt(k);
    e.normal = v.into(k);
    e.centre = e.node + e.normal * plane;
    e.radius = v.radiusAt(v.fromA(k, plane));
    e.open = true;
    e.tight = true;
    e.step = stepNear(v.rmax(), o_.junction);
    return e;
  }

  // A part's surface; a stub whose cut fails (its loop in the plane is not star-shaped around
  // the axis: the node's other vessels or a slid vertex reach into it) is cut again further
  // into its tube, while the tube keeps its length: first the same contour (its overshoot past
  // the plane holds the new one), then, up to kCutRetries times, a contour of the part with
  // its stub shortened. Only this part changes: giving the tube up would join its vessel to
  // the part at its other end too.
  ClusterMesh meshCluster(const Cluster& c) const {
    std::vector<double> plane(c.stubs.size());
    for (std::size_t k = 0; k < c.stubs.size(); ++k) plane[k] = vessels_[std::size_t(c.stubs[k].vessel)].plane[c.stubs[k].side];
    for (int attempt = 0;; ++attempt) {
      ClusterMesh out = meshClusterAt(c, plane);
      out.cut_retries += attempt;
      bool again = false;
      for (std::size_t k = 0; k < c.stubs.size() && attempt < kCutRetries; ++k)
        if (out.loops[k].empty()) again = moveCut(c, k, kCutShift, plane) || again;
      if (!again) {
        out.planes = std::move(plane);
        return out;
      }
    }
  }
  // Moves stub k's cut further into its tube by `shift` radii (or what is left, at least
  // kLeastCutShift): each side may take half of the tube's spare length (the part at the other
  // side may move its cut too). False if there is no room.
  bool moveCut(const Cluster& c, std::size_t k, double shift, std::vector<double>& plane) const {
    const auto& v = vessels_[std::size_t(c.stubs[k].vessel)];
    const double spare = 0.5 * (v.len - v.plane[0] - v.plane[1] - (v.looped ? loopedTubeLength(v) : kShortestTube * v.rmax()));
    const double room = spare - (plane[k] - v.plane[c.stubs[k].side]);
    if (!(room >= kLeastCutShift * v.rmax())) return false;
    plane[k] += std::min(shift * v.rmax(), room);
    return true;
  }
  // `stub_planes`: the cuts asked for, moved where a cut was made again in the same contour.
  ClusterMesh meshClusterAt(const Cluster& c, std::vector<double>& stub_planes) const {
    ClusterMesh out;
    VascularTree sub;
    const auto piece = [&](const Vec3& a, const Vec3& b, double ra, double rb) {
      const auto root = sub.addNode(a, -1, 0);
      const auto id = sub.addNode(b, root);
      sub.radius[id] = rb;
      if (ra != rb) sub.radius_start[id] = ra;
      return id;
    };
    std::vector<VesselEnd> planes;
    for (std::size_t k = 0; k < c.stubs.size(); ++k) {
      const auto& st = c.stubs[k];
      const auto& v = vessels_[std::size_t(st.vessel)];
      const auto e = stubPlane(v, st.side, stub_planes[k]);
      // Prolonged past the plane (the cut's overshoot), then cut away again.
      const double d = stub_planes[k] + kStubOvershoot * e.radius;
      piece(e.node, e.node + e.normal * d, v.radiusAt(v.fromA(st.side, 0)), v.radiusAt(v.fromA(st.side, d)));
      planes.push_back(e);
    }
    // A vessel with a close stretch is split there (collinear pieces with the radii of the
    // capsule's spheres at the splits: the same solid), the middle piece with finer cells.
    std::map<std::int32_t, GapSpan> span_of;
    for (const auto& g : c.gap_spans) {
      const auto it = span_of.find(g.vessel);
      if (it == span_of.end()) {
        span_of.emplace(g.vessel, g);
        continue;
      }
      auto& m = it->second;
      m.cell = std::min(m.cell, g.cell), m.y0 = std::min(m.y0, g.y0), m.y1 = std::max(m.y1, g.y1);
      m.partners.insert(m.partners.end(), g.partners.begin(), g.partners.end());
    }
    std::vector<std::pair<std::int32_t, double>> fine;  // sub segment, its largest cell
    std::map<std::int32_t, std::int32_t> fine_piece;    // vessel → its fine piece
    for (auto i : c.whole) {
      const auto& v = vessels_[std::size_t(i)];
      const auto it = span_of.find(i);
      if (it == span_of.end() || !(v.len > 0)) {
        piece(v.a, v.b, v.ra, v.rb);
      } else {
        const auto at = [&](double y) { return v.a + v.u * y; };
        const auto sphere = [&](double y) { return v.ra + (v.rb - v.ra) * y / v.len; };
        const double y0 = it->second.y0, y1 = it->second.y1;
        if (y0 > 0) piece(v.a, at(y0), v.ra, sphere(y0));
        fine.emplace_back(piece(at(y0), at(y1), sphere(y0), sphere(y1)), it->second.cell);
        fine_piece[i] = fine.back().first;
        if (y1 < v.len) piece(at(y1), v.b, sphere(y1), v.rb);
      }
      for (int k = 0; k < 2; ++k) {
        if (v.end[k] < 0) continue;
        const auto& e = o_.ends[std::size_t(v.end[k])];
        piece(e.node, e.centre + e.normal * e.radius, e.radius, e.radius);  // prolongEnds' prolongation
        out.end_ids.push_back(v.end[k]);
      }
    }
    for (auto e : out.end_ids) planes.push_back(o_.ends[std::size_t(e)]);
    std::vector<double> gap_cells(fine.empty() ? 0 : std::size_t(sub.nodeCount()), 0.0);
    for (const auto& [s, cell] : fine) gap_cells[std::size_t(s)] = cell;
    // Fine cells only near the pieces across each gap (graded away from it).
    std::vector<std::vector<std::int32_t>> gap_partners(gap_cells.size());
    for (const auto& [vessel, s] : fine_piece)
      for (auto q : span_of.at(vessel).partners)
        if (const auto it = fine_piece.find(q); it != fine_piece.end()) gap_partners[std::size_t(s)].push_back(it->second);
    // Marching tetrahedra bridge a wedge between two vessels narrower than a step: a part whose
    // vessels touch nowhere must come out with as many components as its union and without
    // handles, else it is contoured again at twice (then four times) the samples across.
    const int base = std::max(1, o_.junction.samples_across);
    for (int refine = 0;; ++refine) {
      contourCluster(c, sub, planes, stub_planes, base << refine, gap_cells, gap_partners, out);
      if (c.touching || !c.gap_spans.empty() || refine == kRefinements || isUnionShaped(out.mesh, planes, c)) break;
      ++out.refinements;
      for (auto& g : gap_cells) g /= 2;
    }
    return out;
  }

  // A contoured part of genus 0 with `parts` components: 2 × components − boundary loops = V − E + F.
  // Where vessels touch, each contact the contour closes joins two components or makes a handle:
  // from parts_apart components, k closed contacts (0 ≤ k ≤ contacts) leave c components and
  // k − (parts_apart − c) handles.
  static bool isUnionShaped(const SurfaceMesh& m, const std::vector<VesselEnd>& planes, const Cluster& c) {
    const auto topo = meshTopology(m);
    std::int64_t chi = 0, components = 0;
    for (auto e : topo.tree_euler) chi += e;
    for (auto k : topo.tree_components) components += k;
    const std::int64_t twice_handles = 2 * components - std::int64_t(boundaryLoops(m, verticesInPlanes(m, planes)).size()) - chi;
    if (twice_handles < 0 || twice_handles % 2 || components < c.parts || components > c.parts_apart) return false;
    const std::int64_t closed = twice_handles / 2 + c.parts_apart - components;
    return closed <= c.contacts;
  }
  // The part's surface at `samples` across each vessel, cut at its planes, with its stubs' loops.
  void contourCluster(const Cluster& c, const VascularTree& sub, std::vector<VesselEnd>& planes, std::vector<double>& stub_planes, int samples,
                      const std::vector<double>& gap_cells, const std::vector<std::vector<std::int32_t>>& gap_partners, ClusterMesh& out) const {
    SurfaceReport sr;
    SurfaceOptions so = o_.junction;
    so.samples_across = samples;
    so.vessel_max_cell_mm = gap_cells;
    so.vessel_gap_partners = gap_partners;
    EndCutReport cut;
    // Cut while the exact distance is at hand, then decimate (loops and caps stay where they are).
    out.decimation = out.remeshing = DecimateReport();
    const std::size_t ns = c.stubs.size();
    std::vector<std::vector<std::int32_t>> loops;
    so.finish = [&](SurfaceMesh& mesh, const std::function<double(std::int32_t, const Vec3&)>& distance) {
      // Slivers go first, while no cut holds their vertices: marching tetrahedra leave a fan of
      // them where the surface passes by a grid point, and a cut through the fan would keep its
      // edges of a hundredth of a step in the loop (TetGen stops at such features).
      const bool repair = o_.decimation.sliver_deg > 0;
      if (repair) out.slivers = repairSlivers(mesh, o_.decimation, distance);
      // A stub whose loop fails is cut again once, within the contour's overshoot past its plane.
      const SurfaceMesh uncut = ns > 0 ? mesh : SurfaceMesh();
      out.contoured += std::int64_t(mesh.triangles.size());
      std::vector<double> asked = stub_planes;
      for (;;) {
        cut = cutEnds(mesh, planes, o_.cap_ends);
        loops = starLoops(mesh, planes, skipped(cut, ns, planes.size()));
        bool moved = false;
        for (std::size_t k = 0; k < ns; ++k) {
          if (!loops[k].empty() || stub_planes[k] != asked[k] || !moveCut(c, k, kRecutShift, stub_planes)) continue;
          const auto& st = c.stubs[k];
          planes[k] = stubPlane(vessels_[std::size_t(st.vessel)], st.side, stub_planes[k]);
          moved = true;
        }
        if (!moved) break;
        mesh = uncut;
        ++out.cut_retries;
      }
      // Decimated, or only its slivers repaired: the loops keep their vertices, renumbered.
      std::vector<std::int32_t> renumber;
      if (o_.decimate)
        out.decimation = decimate(mesh, o_.decimation, distance, &renumber);
      else if (o_.remesh)
        out.remeshing = remeshIsotropic(mesh, o_.decimation, kRemeshTarget, kRemeshRounds, distance, &renumber);
      else if (repair)
        out.slivers += repairSlivers(mesh, o_.decimation, distance, &renumber, true);
      if (!renumber.empty())
        for (auto& loop : loops) {
          for (auto& p : loop) p = renumber[std::size_t(p)];
          std::erase(loop, -1);  // remeshing collapses the loops' short edges
        }
    };
    // Surface nets where the part allows (about a third of the triangles), checked: on one
    // uniform grid where its radii are alike and no vessels touch, else (radii far apart, gaps
    // to resolve, too large for one grid, or that net refused) on the octree (vesselSurface's
    // dual contour, each vessel at its own step); else, or when the net's cut part is not the
    // union's shape, marching tetrahedra.
    std::optional<SurfaceMesh> net, tetrahedra;
    if (o_.nets) {
      const auto planes_asked = planes;
      const auto stubs_asked = stub_planes;
      // A net whose cut part is not the union's shape is dropped with the cuts it moved.
      const auto keepIfShaped = [&](std::optional<SurfaceMesh>& m) {
        if (m && isUnionShaped(*m, planes, c)) return;
        m.reset();
        planes = planes_asked, stub_planes = stubs_asked;
      };
      NetReport nr;
      if (!c.touching) {
        net = netSurface(sub, so, &sr, &nr);
        keepIfShaped(net);
      }
      if (!net) {
        so.dual = true;
        auto m = vesselSurface(sub, so, &sr);
        so.dual = false;
        if (sr.dual) {
          net = std::move(m);
          keepIfShaped(net);
        } else {
          tetrahedra = std::move(m);  // the dual refused: vesselSurface contoured it by tetrahedra already
        }
      }
    }
    out.netted = net.has_value();
    out.mesh = net ? std::move(*net) : tetrahedra ? std::move(*tetrahedra) : vesselSurface(sub, so, &sr);
    out.estimated_bytes = sr.estimated_bytes;
    out.step = sr.voxel_mm;
    out.cavities_removed = sr.cavities_removed;
    for (auto& tr : out.mesh.triangle_tree) tr = c.tree;
    // The CFD ends' part of the report, and their faces as options.ends numbers them.
    out.ends = EndCutReport();
    out.ends.cut = std::int64_t(out.end_ids.size());
    for (std::size_t k = 0; k < out.end_ids.size(); ++k) {
      out.ends.cap_area_mm2.push_back(cut.cap_area_mm2[ns + k]);
      out.ends.loop_vertices.push_back(cut.loop_vertices[ns + k]);
    }
    for (auto e : cut.left_closed)
      if (std::size_t(e) >= ns) out.ends.left_closed.push_back(out.end_ids[std::size_t(e) - ns]), --out.ends.cut;
    for (auto& f : out.mesh.triangle_face) f = f > std::int32_t(ns) ? out.end_ids[std::size_t(f) - 1 - ns] + 1 : 0;
    // Each stub's loop: the boundary loop in its plane, near its axis, made star-shaped around it.
    out.loops.assign(ns, {});
    if (loops.size() != ns) loops = starLoops(out.mesh, planes, skipped(cut, ns, planes.size()));
    for (std::size_t k = 0; k < ns; ++k) {
      // Counter-clockwise around the vessel's axis a → b (the plane's normal points into the tube).
      if (c.stubs[k].side == 1) std::reverse(loops[k].begin(), loops[k].end());
      out.loops[k] = std::move(loops[k]);
    }
  }

  // The planes starLoops skips: the CFD ends' (after the ns stubs') and the stubs' left closed.
  static std::vector<char> skipped(const EndCutReport& cut, std::size_t ns, std::size_t planes) {
    std::vector<char> skip(planes, 1);
    for (std::size_t k = 0; k < ns; ++k) skip[k] = 0;
    for (auto e : cut.left_closed)
      if (std::size_t(e) < ns) skip[std::size_t(e)] = 1;
    return skip;
  }
  // A ring's radius over its vessel's: 1 on the wall; restoring the volume, what gives the bands
  // between rings the circle's area per length. At the CFD spacing (rings about as far apart as
  // their vertices) successive rings are turned by half a step (`phase` 0 or ½), so the bands'
  // triangles are acute (on aligned rings they were right-angled, and a tetrahedral mesher
  // splits the long edge of every such pair); such a band is a prismatoid whose middle section
  // is the 2n-gon of radius cos(π/2n), so it holds (1 + 2 cos²(π/2n) / cos(π/n)) / 3 of its
  // rings' polygon area per length. Rings radii apart are aligned: their triangles are long
  // whatever their turn, and a band between aligned rings is a frustum of a pyramid, its volume
  // exact for any length however far the ring next to it is turned or scaled.
  // `face`: a ring whose polygon has the circle's area (a CFD end's: its cap).
  bool staggered() const { return o_.ring_spacing_radii <= 0; }
  double ringPhase(std::size_t j) const { return staggered() && j % 2 ? 0.5 : 0.0; }
  double ringScale(int n, bool face = false) const {
    if (!o_.junction.restore_volume) return 1.0;
    const double step = kTwoPi / n, polygon = std::sin(step) / step;  // the n-gon's area over its circle's
    const double middle = std::pow(std::cos(step / 4), 2) / std::cos(step / 2);
    return 1 / std::sqrt(polygon * (face || !staggered() ? 1.0 : (1 + 2 * middle) / 3));
  }
  // Rings from a contoured loop of `n_loop` vertices at y = `from` towards `n_ring`: each about
  // 1.5 times fewer, an equilateral triangle's height of their mean spacing apart, the last one
  // of n_ring; at most `room` (signed: the direction) from the loop; empty when the loop has not
  // 1.3 times the ring's vertices or there is no room.
  std::vector<std::pair<double, int>> graded(const Vessel& v, int n_loop, int n_ring, double from, double room) const {
    std::vector<std::pair<double, int>> out;
    if (n_loop <= 1.3 * n_ring) return out;
    const double dir = room < 0 ? -1 : 1;
    double y = from;
    for (int n = n_loop; n != n_ring;) {
      const int next = n > 1.3 * n_ring ? std::max(n_ring, int(std::lround(n / 1.5))) : n_ring;
      y += dir * 0.5 * std::sqrt(3.0) * std::numbers::pi * v.radiusAt(y) * (1.0 / n + 1.0 / next);
      if ((y - from) * dir > std::abs(room)) return {};
      out.emplace_back(y, next);
      n = next;
    }
    return out;
  }

  // A ring of n vertices around the axis at distance y from a, its first at `phase` steps.
  void ring(SurfaceMesh& m, const Vessel& v, double y, int n, double phase, std::vector<std::int32_t>& out, bool face = false) const {
    Vec3 e1, e2;
    frameOf(v.u, e1, e2);
    const double r = v.radiusAt(y), step = kTwoPi / n;
    const double R = r * ringScale(n, face);
    const Vec3 c = v.a + v.u * y;
    out.clear();
    for (int k = 0; k < n; ++k) {
      const double phi = step * (k + phase);
      out.push_back(std::int32_t(m.vertices.size()));
      m.vertices.push_back(c + (e1 * std::cos(phi) + e2 * std::sin(phi)) * R);
      m.vertex_step.push_back(float(step * R));
    }
  }

  // A round end of rings: latitude rings on the sphere of the end's radius around its node, and
  // its pole. The rings' polygons keep the tube's area correction, and the whole cap is scaled
  // so its volume is the hemisphere's (on_surface: every vertex on the sphere).
  void roundCap(SurfaceMesh& m, const Vessel& v, int k, const std::vector<std::int32_t>& base, int n, double phase) const {
    const int bands = std::max(2, int(std::lround(n / 4.0)));
    const bool restore = o_.junction.restore_volume;
    const double step = kTwoPi / n, area = ringScale(n);
    const double f = restore ? capScale(n, bands, area) : 1.0;
    const double r = v.radiusAt(k == 0 ? 0.0 : v.len);
    const Vec3 node = v.nodeAt(k), out = v.into(k) * -1.0;
    Vec3 e1, e2;
    frameOf(v.u, e1, e2);
    std::vector<std::vector<std::int32_t>> rings{base};
    for (int j = 1; j < bands; ++j) {
      const double phi = std::numbers::pi / 2 * j / bands;
      std::vector<std::int32_t> ring;
      for (int q = 0; q < n; ++q) {
        const double a = step * (q + phase);
        ring.push_back(std::int32_t(m.vertices.size()));
        m.vertices.push_back(node + out * (f * r * std::sin(phi)) + (e1 * std::cos(a) + e2 * std::sin(a)) * (f * area * r * std::cos(phi)));
        m.vertex_step.push_back(float(step * r));
      }
      rings.push_back(std::move(ring));
    }
    const auto pole = std::int32_t(m.vertices.size());
    m.vertices.push_back(node + out * (f * r));
    m.vertex_step.push_back(float(step * r));
    // Ring after ring away from the node; zip takes the ring nearer a first.
    for (std::size_t j = 0; j + 1 < rings.size(); ++j) {
      if (k == 1)
        zipRings(m, v.a, v.u, rings[j], rings[j + 1], v.tree);
      else
        zipRings(m, v.a, v.u, rings[j + 1], rings[j], v.tree);
    }
    const auto& last = rings.back();
    for (std::size_t q = 0; q < last.size(); ++q) {
      const auto p0 = last[q], p1 = last[(q + 1) % last.size()];
      if (k == 1)
        m.triangles.push_back({p0, p1, pole});
      else
        m.triangles.push_back({pole, p1, p0});
      m.triangle_tree.push_back(v.tree);
      m.triangle_face.push_back(0);
    }
  }
  // The scale of a cap's rings and pole (its base ring fixed, of radius `area`) that gives it the
  // volume of the unit hemisphere: bisection on the divergence theorem's volume.
  static double capScale(int n, int bands, double area) {
    const auto volume = [&](double f) {
      std::vector<std::vector<Vec3>> rings;
      for (int j = 0; j < bands; ++j) {
        const double phi = std::numbers::pi / 2 * j / bands, s = j == 0 ? 1.0 : f;
        std::vector<Vec3> ring;
        for (int q = 0; q < n; ++q) {
          const double a = kTwoPi * q / n;
          ring.push_back(Vec3(std::cos(a) * s * area * std::cos(phi), std::sin(a) * s * area * std::cos(phi), s * std::sin(phi)));
        }
        rings.push_back(ring);
      }
      const Vec3 pole(0, 0, f);
      double six = 0;  // the cap closed by its base polygon (at z = 0, adding nothing)
      const auto tri = [&](const Vec3& a, const Vec3& b, const Vec3& c) { six += dot(a, cross(b, c)); };
      for (std::size_t j = 0; j + 1 < rings.size(); ++j)
        for (int q = 0; q < n; ++q) {
          const auto& A = rings[j];
          const auto& B = rings[j + 1];
          tri(A[std::size_t(q)], A[std::size_t((q + 1) % n)], B[std::size_t(q)]);
          tri(A[std::size_t((q + 1) % n)], B[std::size_t((q + 1) % n)], B[std::size_t(q)]);
        }
      for (int q = 0; q < n; ++q) tri(rings.back()[std::size_t(q)], rings.back()[std::size_t((q + 1) % n)], pole);
      return six / 6;
    };
    const double want = 2 * std::numbers::pi / 3;
    double lo = 0.8, hi = 1.3;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (volume(mid) < want ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }

  SurfaceMesh assemble(const std::vector<Cluster>& clusters, std::vector<ClusterMesh>& meshes, TubeSurfaceReport& rep) const {
    SurfaceMesh m;
    m.triangle_face.clear();
    // Where each tube's end loops are in the joined mesh.
    std::vector<std::array<std::vector<std::int32_t>, 2>> loops(vessels_.size());
    rep.ends.cap_area_mm2.assign(o_.ends.size(), 0.0);
    rep.ends.loop_vertices.assign(o_.ends.size(), 0);
    for (std::size_t c = 0; c < clusters.size(); ++c) {
      auto& cm = meshes[c];
      const auto base = std::int32_t(m.vertices.size());
      m.vertices.insert(m.vertices.end(), cm.mesh.vertices.begin(), cm.mesh.vertices.end());
      m.vertex_step.insert(m.vertex_step.end(), cm.mesh.vertex_step.begin(), cm.mesh.vertex_step.end());
      for (auto t : cm.mesh.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
      m.triangle_tree.insert(m.triangle_tree.end(), cm.mesh.triangle_tree.begin(), cm.mesh.triangle_tree.end());
      m.triangle_face.insert(m.triangle_face.end(), cm.mesh.triangle_face.begin(), cm.mesh.triangle_face.end());
      rep.contour_triangles += std::int64_t(cm.mesh.triangles.size());
      rep.contoured_triangles += cm.contoured;
      rep.netted += cm.netted;
      rep.cavities_removed += cm.cavities_removed;
      rep.refinements += cm.refinements;
      rep.cut_retries += cm.cut_retries;
      rep.triangles_before_decimation += cm.decimation.before;
      rep.decimation_collapses += cm.decimation.collapses;
      rep.slivers_repaired += cm.slivers.changes();
      rep.remesh_splits += cm.remeshing.splits, rep.remesh_changes += cm.remeshing.changes();
      rep.decimation_largest_error_mm = std::max(rep.decimation_largest_error_mm, cm.decimation.largest_error_mm);
      rep.estimated_bytes = std::max(rep.estimated_bytes, cm.estimated_bytes);
      rep.finest_step_mm = rep.finest_step_mm > 0 ? std::min(rep.finest_step_mm, cm.step) : cm.step;
      rep.largest_cluster_vessels =
          std::max<std::int64_t>(rep.largest_cluster_vessels, std::int64_t(clusters[c].whole.size() + clusters[c].stubs.size()));
      for (std::size_t k = 0; k < clusters[c].stubs.size(); ++k) {
        auto& l = loops[std::size_t(clusters[c].stubs[k].vessel)][std::size_t(clusters[c].stubs[k].side)];
        for (auto p : cm.loops[k]) l.push_back(p + base);
      }
      for (std::size_t k = 0; k < cm.end_ids.size(); ++k) {
        const auto e = std::size_t(cm.end_ids[k]);
        rep.ends.cap_area_mm2[e] = cm.ends.cap_area_mm2[k];
        rep.ends.loop_vertices[e] = cm.ends.loop_vertices[k];
      }
      rep.ends.cut += cm.ends.cut;
      rep.ends.left_closed.insert(rep.ends.left_closed.end(), cm.ends.left_closed.begin(), cm.ends.left_closed.end());
      SurfaceMesh().vertices.swap(cm.mesh.vertices);
    }
    rep.clusters = std::int64_t(clusters.size());
    // The tubes, ring to ring.
    const auto before = m.triangles.size();
    std::vector<std::int32_t> A, B;
    for (std::size_t i = 0; i < vessels_.size(); ++i) {
      const auto& v = vessels_[i];
      if (!v.tube) continue;
      ++rep.tubes;
      const double y0 = v.plane[0], y1 = v.len - v.plane[1];
      const int n_ring = ringVertices(v);
      // Rings at most ring_spacing_radii radii apart. A contoured loop has several times a
      // ring's vertices: zipped to a ring two radii away, its band fans out into triangles of a
      // few degrees (a quarter of the tube's triangles were under 5°), so the first ring stands
      // kLoopBand radii from it.
      const bool band0 = !v.round[0] && v.end[0] < 0, band1 = !v.round[1] && v.end[1] < 0;  // a contoured loop at that side
      // Remeshing, the loop's vertices thin out to the ring's over rings of fewer and fewer
      // (graded()): fanned onto one ring, half its band's triangles were obtuse.
      std::vector<std::pair<double, int>> graded0, graded1;  // (position, vertices) from the loop inwards
      if (o_.remesh && band0) graded0 = graded(v, int(loops[i][0].size()), n_ring, y0, (y1 - y0) / 3);
      if (o_.remesh && band1) graded1 = graded(v, int(loops[i][1].size()), n_ring, y1, -(y1 - y0) / 3);
      const double lo = !band0 ? y0 : !graded0.empty() ? graded0.back().first : std::min(y0 + kLoopBand * v.radiusAt(y0), y0 + (y1 - y0) / 3);
      const double hi = !band1 ? y1 : !graded1.empty() ? graded1.back().first : std::max(y1 - kLoopBand * v.radiusAt(y1), y1 - (y1 - y0) / 3);
      // The rings between the ends: where, how many vertices, and whether the ring has the
      // circle's area itself (next to a contoured loop, and graded: their bands are no prismatoids).
      struct RingAt {
        double y;
        int n;
        bool exact;
      };
      std::vector<RingAt> at;
      for (const auto& [y, n] : graded0) at.push_back({y, n, true});
      if (band0 && graded0.empty()) at.push_back({lo, n_ring, true});
      const double spacing =
          (o_.ring_spacing_radii > 0 ? o_.ring_spacing_radii : kCfdRingSpacing * kTwoPi / n_ring) * 0.5 * (v.radiusAt(y0) + v.radiusAt(y1));
      const int pieces = std::max(1, int(std::ceil((hi - lo) / std::max(spacing, 1e-12))));
      for (int q = 1; q < pieces; ++q) at.push_back({lo + (hi - lo) * q / pieces, n_ring, false});
      if (band1 && graded1.empty()) at.push_back({hi, n_ring, true});
      for (auto g = graded1.rbegin(); g != graded1.rend(); ++g) at.push_back({g->first, g->second, true});
      // Ring j of the tube (0 at y0, at.size() + 1 at y1), turned by j half steps if staggered.
      const auto phase = [this](std::size_t j) { return ringPhase(j); };
      for (int k = 0; k < 2; ++k) {
        auto& l = loops[i][std::size_t(k)];
        const double turn = phase(k == 0 ? 0 : at.size() + 1);
        if (v.round[k]) {
          ring(m, v, k == 0 ? y0 : y1, n_ring, turn, l);
          roundCap(m, v, k, l, n_ring, turn);
          continue;
        }
        if (v.end[k] < 0) continue;
        // A CFD end: its ring in its plane, open or capped.
        ring(m, v, k == 0 ? y0 : y1, n_ring, turn, l, true);
        const auto& e = o_.ends[std::size_t(v.end[k])];
        ++rep.ends.cut;
        rep.ends.loop_vertices[std::size_t(v.end[k])] = std::int32_t(l.size());
        if (!o_.cap_ends) continue;
        const auto centre = std::int32_t(m.vertices.size());
        m.vertices.push_back(e.centre);
        m.vertex_step.push_back(m.vertex_step[std::size_t(l[0])]);
        double area = 0;
        for (std::size_t q = 0; q < l.size(); ++q) {
          const auto p0 = l[q], p1 = l[(q + 1) % l.size()];
          // Outward: +u at the distal end, −u at the proximal one.
          if (k == 1)
            m.triangles.push_back({centre, p0, p1});
          else
            m.triangles.push_back({centre, p1, p0});
          m.triangle_tree.push_back(v.tree);
          m.triangle_face.push_back(v.end[k] + 1);
          area += 0.5 * norm(cross(m.vertices[std::size_t(p0)] - e.centre, m.vertices[std::size_t(p1)] - e.centre));
        }
        rep.ends.cap_area_mm2[std::size_t(v.end[k])] = area;
      }
      A = loops[i][0];
      for (std::size_t q = 0; q <= at.size(); ++q) {
        if (q < at.size())
          ring(m, v, at[q].y, at[q].n, phase(q + 1), B, at[q].exact);
        else
          B = loops[i][1];
        const bool at_loop = (band0 && q == 0) || (band1 && q == at.size());
        zipRings(m, v.a, v.u, A, B, v.tree, 0, o_.remesh && at_loop);
        A = B;
      }
    }
    rep.tube_triangles = std::int64_t(m.triangles.size() - before);
    if (o_.ends.empty()) m.triangle_face.clear();  // no labelled faces without cut ends
    std::sort(rep.ends.left_closed.begin(), rep.ends.left_closed.end());
    return m;
  }

  const VascularTree& t_;
  const TubeSurfaceOptions& o_;
  std::vector<Vessel> vessels_;
  std::unordered_map<std::int32_t, std::int32_t> index_of_;  // segment id → vessel index
  std::vector<std::vector<const Vessel*>> at_node_;          // per junction node, its vessels
  std::vector<ClosePair> close_pairs_;
};

}  // namespace

SurfaceMesh tubeSurface(const VascularTree& forest, const TubeSurfaceOptions& options, TubeSurfaceReport* report,
                        const std::function<void(std::int64_t, std::int64_t)>& progress) {
  TubeSurfaceReport local;
  TubeSurfaceReport& rep = report ? *report : local;
  rep = TubeSurfaceReport();
  TubeMesher mesher(forest, options);
  return mesher.run(rep, progress);
}

}  // namespace angiosynth
