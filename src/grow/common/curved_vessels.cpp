#include "grow/common/curved_vessels.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "core/error.hpp"
#include "core/memory.hpp"
#include "core/polyline_turns.hpp"
#include "core/rng.hpp"
#include "domain/growth_domain.hpp"
#include "grow/common/intersections.hpp"
#include "core/segment_grid.hpp"

namespace angiosynth {

std::vector<VesselPath> vesselPaths(const VascularTree& t) {
  std::vector<VesselPath> out;
  for (std::int32_t n = 0; n < t.nodeCount(); ++n) {
    if (t.isRoot(n) || t.type(t.parent[n]) == NodeType::Continuation) continue;
    VesselPath v;
    v.start = t.parent[n];
    for (std::int32_t s = n;; s = t.child0[s]) {
      v.segments.push_back(s);
      if (t.type(s) != NodeType::Continuation) break;
    }
    out.push_back(std::move(v));
  }
  return out;
}

double distanceMetric(const VascularTree& t, const VesselPath& v) {
  double arc = 0;
  for (auto s : v.segments) arc += distance(t.position[t.parent[s]], t.position[s]);
  const double chord = distance(t.position[v.start], t.position[v.segments.back()]);
  return chord > 0 ? arc / chord : 1.0;
}

namespace {

constexpr int kLevels = 7;  // amplitude halvings before a vessel is left as growth made it

// One vessel's path as growth made it, its random knots, and its curve at a given amplitude.
struct VesselCurve {
  const VascularTree* t = nullptr;
  VesselPath path;
  std::vector<Vec3> base;   // path points: start, then each segment's distal node
  std::vector<double> arc;  // arc length of the path at each point
  std::vector<int> pieces;  // pieces of each segment
  std::vector<Vec3> knot;   // displacement at the knots per unit amplitude (0 at both ends)
  double chord = 0, target = 1, amplitude = 0;
  int level = 0;  // halvings applied
  bool moved = false, own_path_enough = false, flattened_by_domain = false, flattened_by_overlap = false;
  std::vector<Vec3> points;     // the curve: every piece's distal point, in order
  std::vector<double> piece_u;  // path arc length at each of them

  double length() const { return arc.back(); }
  Vec3 pathAt(double u, std::size_t& seg) const {
    while (seg + 2 < arc.size() && arc[seg + 1] < u) ++seg;
    const double l = arc[seg + 1] - arc[seg];
    const double f = l > 0 ? std::clamp((u - arc[seg]) / l, 0.0, 1.0) : 1.0;
    return base[seg] + (base[seg + 1] - base[seg]) * f;
  }
  // Catmull-Rom through the knots, mirrored past the ends so the curve leaves each end smoothly.
  Vec3 displacement(double u) const {
    const int m = int(knot.size()) - 1;
    const double x = std::clamp(u / length(), 0.0, 1.0) * m;
    const int k = std::min(int(x), m - 1);
    const double s = x - k;
    const auto at = [&](int i) { return i < 0 ? knot[std::size_t(-i)] * -1.0 : i > m ? knot[std::size_t(2 * m - i)] * -1.0 : knot[std::size_t(i)]; };
    const Vec3 p0 = at(k - 1), p1 = at(k), p2 = at(k + 1), p3 = at(k + 2);
    const double s2 = s * s, s3 = s2 * s;
    return (p1 * 2.0 + (p2 - p0) * s + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * s2 + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * s3) * 0.5;
  }
  void draw(double a) {
    points.clear();
    piece_u.clear();
    std::size_t seg = 0;
    for (std::size_t j = 0; j + 1 < base.size(); ++j)
      for (int q = 1; q <= pieces[j]; ++q) {
        const double u = arc[j] + (arc[j + 1] - arc[j]) * double(q) / pieces[j];
        Vec3 p = pathAt(u, seg);
        if (a > 0) p = p + displacement(u) * a;
        if (q == pieces[j] && j + 2 == base.size()) p = base.back();  // the far end stays exactly
        points.push_back(p);
        piece_u.push_back(u);
      }
  }
  double metric() const {
    double l = 0;
    Vec3 prev = base[0];
    for (const auto& p : points) l += distance(prev, p), prev = p;
    return chord > 0 ? l / chord : 1.0;
  }
  // Σ angles / length of the curve (rad/mm), as `stats` measures a vessel.
  double sumOfAngles() const {
    std::vector<Vec3> line{base[0]};
    line.insert(line.end(), points.begin(), points.end());
    double l = 0;
    for (std::size_t k = 1; k < line.size(); ++k) l += distance(line[k - 1], line[k]);
    return l > 0 ? polylineTurns(line).total_angle / l : 0.0;
  }
  double measure(bool by_angles) const { return by_angles ? sumOfAngles() : metric(); }
  double radiusOfPiece(std::size_t i, std::size_t& seg) const {
    while (seg + 1 < path.segments.size() && piece_u[i] > arc[seg + 1]) ++seg;
    const auto s = path.segments[seg];
    return t->maxRadius(s) + std::max(t->wall[s], t->wall_start[s]);  // the outer wall, where one is given
  }
};

Vec3 perpendicular(const Vec3& d) {
  const Vec3 a = std::fabs(d.x) < 0.6 ? Vec3(1, 0, 0) : std::fabs(d.y) < 0.6 ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
  return unit(cross(d, a));
}

struct Bounds {
  const GrowthDomain* domain;
  const DemandMap& frame;
  double clearance;
  // Each curve point is held to what the path point it replaces met: as deep inside the domain
  // as the radius and clearance ask (or as the path point was, if less), and on perfusable voxels
  // where the path was.
  bool fits(const VesselCurve& c) const {
    std::size_t seg = 0, rseg = 0;
    Vec3 prev = c.base[0];
    double u_prev = 0;
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      const double r = c.radiusOfPiece(i, rseg);
      const double u = c.piece_u[i];
      // The piece's middle, then its far end (path positions ascend, so one walk serves both).
      if (!fitsAt((prev + c.points[i]) * 0.5, c.pathAt((u_prev + u) / 2, seg), r)) return false;
      if (!fitsAt(c.points[i], c.pathAt(u, seg), r)) return false;
      prev = c.points[i], u_prev = u;
    }
    return true;
  }
  // A frame without demand (Lázaro's block) bounds by its box alone.
  bool open(const Vec3& p) const { return frame.demand.empty() ? frame.voxelAt(p) >= 0 : frame.perfusable(p); }
  bool fitsAt(const Vec3& p, const Vec3& q, double r) const {
    if (open(q) && !open(p)) return false;
    return !domain || domain->depth(p) >= std::min(r + clearance, domain->depth(q)) - 1e-9;
  }
};

// The pieces' length along a vessel of `length` mm, `knots` knot intervals and largest radius r:
// the longest piece asked for, and each knot interval at least 8 pieces so the curve is resolved
// as well as the voxels; never under an eighth of the radius, where a finer curve changes nothing
// and every piece would be checked against the hundreds beside it on its own vessel.
double pieceStep(double piece, double length, int knots, double r) { return std::max(std::min(piece, length / (8.0 * knots)), r / 8); }

// Vessels that overlap where their straight forms did not; pairs of pieces near a shared end (or
// near each other along one vessel) touch by construction and are not counted.
struct PieceOverlaps {
  std::vector<Vec3> a, b;
  std::vector<double> r, u;
  std::vector<std::int32_t> vessel;
  double mean_extent = 1;

  void collect(const std::vector<VesselCurve>& curves) {
    a.clear(), b.clear(), r.clear(), u.clear(), vessel.clear();
    double extent = 0;
    for (std::size_t v = 0; v < curves.size(); ++v) {
      const auto& c = curves[v];
      Vec3 prev = c.base[0];
      std::size_t seg = 0;
      for (std::size_t i = 0; i < c.points.size(); ++i) {
        a.push_back(prev), b.push_back(c.points[i]);
        r.push_back(c.radiusOfPiece(i, seg));
        u.push_back(c.piece_u[i]);
        vessel.push_back(std::int32_t(v));
        extent += distance(prev, c.points[i]) + 2 * r.back();
        prev = c.points[i];
      }
    }
    mean_extent = a.empty() ? 1 : extent / double(a.size());
  }

  std::set<std::pair<std::int32_t, std::int32_t>> pairs(const std::vector<VesselCurve>& curves, bool flat) {
    collect(curves);
    std::set<std::pair<std::int32_t, std::int32_t>> out;
    if (a.empty()) return out;
    Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
    for (std::size_t i = 0; i < a.size(); ++i) {
      lo = componentMin(componentMin(lo, a[i]), b[i]);
      hi = componentMax(componentMax(hi, a[i]), b[i]);
    }
    SegmentGrid grid(lo, hi, 2 * mean_extent, flat);
    for (std::size_t i = 0; i < a.size(); ++i) grid.insert(std::int32_t(i), a[i], b[i], r[i]);
    for (std::size_t x = 0; x < a.size(); ++x)
      grid.any(a[x], b[x], r[x], [&](std::int32_t y) {
        if (std::size_t(y) <= x || !capsulesOverlap(a[x], b[x], r[x], a[y], b[y], r[y])) return false;
        const auto vx = vessel[x], vy = vessel[y];
        const double near = 4 * (r[x] + r[y]) + distance(a[x], b[x]) + distance(a[y], b[y]);
        if (vx == vy) {
          if (std::fabs(u[x] - u[std::size_t(y)]) <= near) return false;
        } else if (const double along = sharedEndDistance(curves, x, std::size_t(y)); along >= 0 && along <= near) {
          return false;
        }
        out.emplace(std::min(vx, vy), std::max(vx, vy));
        return false;
      });
    return out;
  }

  // The larger of the two pieces' path distances from an end node their vessels share; −1 if none.
  double sharedEndDistance(const std::vector<VesselCurve>& curves, std::size_t x, std::size_t y) const {
    const auto& cx = curves[std::size_t(vessel[x])];
    const auto& cy = curves[std::size_t(vessel[y])];
    const std::int32_t ends_x[2] = {cx.path.start, cx.path.segments.back()}, ends_y[2] = {cy.path.start, cy.path.segments.back()};
    double best = -1;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        if (ends_x[i] == ends_y[j]) {
          const double dx = i == 0 ? u[x] : cx.length() - u[x], dy = j == 0 ? u[y] : cy.length() - u[y];
          const double d = std::max(dx, dy);
          if (best < 0 || d < best) best = d;
        }
    return best;
  }
};

}  // namespace

VascularTree curveVessels(const VascularTree& t, const CurveOptions& o, const GrowthDomain* domain, const DemandMap& frame, std::uint64_t seed,
                          std::uint64_t sample, CurveReport& rep, std::uint64_t memory_limit) {
  rep = CurveReport{};
  rep.nodes_before = t.nodeCount();
  const auto paths = vesselPaths(t);
  rep.vessels = std::int64_t(paths.size());
  const bool flat = frame.dims[2] == 1;
  const double piece = o.piece_mm.value_or(frame.voxel_mm);
  const Bounds bounds{domain, frame, o.wall_clearance_mm};
  const bool by_angles = o.sum_of_angles.has_value();
  rep.target_sum_of_angles = by_angles;

  // The pieces before anything is drawn (each knot interval gets at least 8, as below): a piece
  // length far below the vessels makes millions of nodes, drawn some ninety times each while the
  // amplitude is sought.
  double pieces = 0;
  for (const auto& path : paths) {
    double length = 0, r = 0;
    std::int32_t prev = path.start;
    std::vector<double> arcs;
    for (auto seg : path.segments) {
      arcs.push_back(distance(t.position[prev], t.position[seg]));
      length += arcs.back();
      r = std::max(r, t.maxRadius(seg));
      prev = seg;
    }
    const double wavelength = o.wavelength(r);
    const int m = std::clamp(int(std::lround(2 * length / std::max(wavelength, 1e-12))), 2, 4096);
    const double step = pieceStep(piece, length, m, r);
    for (double a : arcs) pieces += std::max(1.0, std::ceil(a / std::max(step, 1e-12) - 1e-9));
  }
  constexpr double kBytesPerPiece = 400;  // its points (curve, straight copy, overlap index) and its node in the tree
  if (pieces > double(std::numeric_limits<std::int32_t>::max() / 2) || (memory_limit > 0 && pieces * kBytesPerPiece > double(memory_limit)))
    throw InputError("", 0,
                     "[curves] piece_length " + std::to_string(piece) + " mm draws the vessels in about " + std::to_string(std::llround(pieces)) +
                         " pieces, which need about " + formatBytes(std::uint64_t(pieces * kBytesPerPiece)) + ", more than the limit of " +
                         formatBytes(memory_limit) + "; allowed: a longer piece_length (default: one voxel) or a larger --memory-limit");

  std::vector<VesselCurve> curves(paths.size());
  const auto build = [&](VesselCurve& c) {
    const double a = c.level >= kLevels ? 0.0 : std::ldexp(c.amplitude, -c.level);  // halved `level` times
    c.draw(a);
    c.moved = a > 0;
  };
  tbb::parallel_for(std::size_t(0), paths.size(), [&](std::size_t v) {
    auto& c = curves[v];
    c.t = &t;
    c.path = paths[v];
    c.base.push_back(t.position[c.path.start]);
    c.arc.push_back(0);
    double r = 0;
    for (auto s : c.path.segments) {
      c.base.push_back(t.position[s]);
      c.arc.push_back(c.arc.back() + distance(c.base[c.base.size() - 2], c.base.back()));
      r = std::max(r, t.maxRadius(s));
    }
    c.chord = distance(c.base.front(), c.base.back());
    Rng rng(seed, sample, Stage::Curves, std::uint64_t(c.path.segments.front()));
    const double spread = rng.normal();
    c.target = by_angles ? std::max(0.0, *o.sum_of_angles * (1 + o.tortuosity_sd * spread)) : std::max(1.0, o.tortuosity + o.tortuosity_sd * spread);
    const double wavelength = o.wavelength(r);
    const int m = std::clamp(int(std::lround(2 * c.length() / std::max(wavelength, 1e-12))), 2, 4096);
    const double step = pieceStep(piece, c.length(), m, r);
    for (std::size_t j = 0; j + 1 < c.base.size(); ++j)
      c.pieces.push_back(std::max(1, int(std::ceil((c.arc[j + 1] - c.arc[j]) / std::max(step, 1e-12) - 1e-9))));
    c.knot.assign(std::size_t(m) + 1, Vec3(0, 0, 0));
    std::size_t seg = 0;
    for (int k = 1; k < m; ++k) {
      const double u = c.length() * k / m;
      c.pathAt(u, seg);
      Vec3 d = c.base[seg + 1] - c.base[seg];
      d = norm(d) > 0 ? unit(d) : Vec3(0, 0, 1);
      // The knot offsets are drawn whatever the target, so a vessel's curve does not depend on others.
      const double x1 = rng.normal(), x2 = rng.normal();
      const Vec3 e1 = flat ? unit(cross(d, Vec3(0, 0, 1))) : perpendicular(d), e2 = cross(d, e1);
      c.knot[std::size_t(k)] = (e1 * x1 + (flat ? Vec3(0, 0, 0) : e2 * x2)) * (c.length() / m);
    }
    c.draw(0);
    const double own = c.measure(by_angles);
    if (c.chord <= 0 || own >= c.target) {
      c.own_path_enough = own >= c.target && c.target > (by_angles ? 0 : 1);
      return;
    }
    // The metric (or the sum of angles) grows with the amplitude, least at 0 for a straight path.
    double lo = 0, hi = 0.25;
    for (int i = 0; i < 40; ++i) {
      c.draw(hi);
      if (c.measure(by_angles) >= c.target) break;
      lo = hi, hi *= 2;
    }
    for (int i = 0; i < 50 && hi - lo > 1e-12 * hi; ++i) {
      const double mid = (lo + hi) / 2;
      c.draw(mid);
      (c.measure(by_angles) < c.target ? lo : hi) = mid;
    }
    c.amplitude = (lo + hi) / 2;
    for (c.level = 0;; ++c.level) {
      build(c);
      if (!c.moved || bounds.fits(c)) break;
      c.flattened_by_domain = true;
    }
  });

  if (o.avoid_overlaps) {
    // Pairs that overlap in growth's own shapes are not the curves' doing: drawn straight once.
    std::vector<VesselCurve> straight = curves;
    tbb::parallel_for(std::size_t(0), straight.size(), [&](std::size_t v) { straight[v].draw(0); });
    PieceOverlaps finder;
    const auto grown = finder.pairs(straight, flat);
    for (;;) {
      auto found = finder.pairs(curves, flat);
      std::vector<std::int32_t> redo;
      std::set<std::int32_t> seen;
      for (const auto& pr : found) {
        if (grown.count(pr)) continue;
        for (auto v : {pr.first, pr.second})
          if (curves[std::size_t(v)].moved && seen.insert(v).second) redo.push_back(v);
      }
      std::int64_t left = 0;
      for (const auto& pr : found) left += grown.count(pr) ? 0 : 1;
      rep.overlapping_vessel_pairs = left;
      if (redo.empty()) break;
      ++rep.overlap_rounds;
      tbb::parallel_for(std::size_t(0), redo.size(), [&](std::size_t i) {
        auto& c = curves[std::size_t(redo[i])];
        c.flattened_by_overlap = true;
        ++c.level;
        build(c);
      });
    }
  }

  // The tree: pieces in place of segments, attributes from the segment each piece replaces.
  struct Place {
    std::int32_t vessel = -1, index = -1, first_piece = -1;  // the segment's vessel, its place in it, its first piece
  };
  std::vector<Place> where(t.nodeCount());
  for (std::size_t v = 0; v < curves.size(); ++v) {
    std::int32_t first = 0;
    for (std::size_t j = 0; j < curves[v].path.segments.size(); ++j) {
      where[curves[v].path.segments[j]] = {std::int32_t(v), std::int32_t(j), first};
      first += curves[v].pieces[j];
    }
  }
  VascularTree w;
  w.reserve(t.nodeCount());
  std::vector<std::int32_t> node_of(t.nodeCount(), -1);
  for (std::int32_t n : t.topDownOrder()) {
    if (t.isRoot(n)) {
      node_of[n] = w.addNode(t.position[n], -1, t.tree[n]);
      w.pressure[node_of[n]] = t.pressure[n];
      w.depth[node_of[n]] = t.depth[n];
      continue;
    }
    const Place& at = where[n];
    const auto& c = curves[std::size_t(at.vessel)];
    const int k = c.pieces[std::size_t(at.index)];
    // Poiseuille: the pressure falls (or rises, in a vein) linearly with the length along a vessel.
    const double gradient = t.length[n] > 0 ? (t.pressure[t.parent[n]] - t.pressure[n]) / t.length[n] : 0.0;
    std::int32_t prev = node_of[t.parent[n]];
    for (int q = 1; q <= k; ++q) {
      const Vec3& p = c.points[std::size_t(at.first_piece + q - 1)];
      const std::int32_t id = w.addNode(p, prev);
      w.setPieceOf(t, n, q, k, id);
      w.pressure[id] = w.pressure[prev] - gradient * w.length[id];
      w.beta[id] = q == 1 ? t.beta[n] : 1.0;
      w.stage[id] = t.stage[n];
      w.role[id] = t.role[n];
      w.branching[id] = t.branching[n];
      w.outflow[id] = q == k ? t.outflow[n] : 0.0;
      prev = id;
    }
    node_of[n] = prev;
  }

  rep.nodes_after = w.nodeCount();
  double sum = 0;
  rep.tortuosity_min = INFINITY, rep.tortuosity_max = 0;
  for (const auto& c : curves) {
    const double dm = c.metric();
    sum += dm;
    rep.tortuosity_min = std::min(rep.tortuosity_min, dm);
    rep.tortuosity_max = std::max(rep.tortuosity_max, dm);
    rep.curved += c.moved ? 1 : 0;
    rep.already_tortuous += c.own_path_enough ? 1 : 0;
    rep.flattened_by_domain += c.flattened_by_domain ? 1 : 0;
    rep.flattened_by_overlap += c.flattened_by_overlap ? 1 : 0;
    rep.straightened += (c.amplitude > 0 && !c.moved) ? 1 : 0;
    if (c.moved && c.level == 0) rep.target_error_max = std::max(rep.target_error_max, std::fabs((by_angles ? c.sumOfAngles() : dm) - c.target));
  }
  if (curves.empty()) rep.tortuosity_min = rep.tortuosity_max = 1;
  rep.tortuosity_mean = curves.empty() ? 1 : sum / double(curves.size());
  return w;
}

}  // namespace angiosynth
