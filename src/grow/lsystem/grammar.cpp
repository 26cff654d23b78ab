#include "grow/lsystem/grammar.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "core/physical_ranges.hpp"
#include "core/rng.hpp"
#include "grow/common/intersections.hpp"
#include "core/segment_grid.hpp"
#include "physics/hemodynamics.hpp"

namespace angiosynth {

namespace {

constexpr double kDeg = std::numbers::pi / 180;

// Rodrigues: v rotated by angle a about the unit axis k.
Vec3 rotate(const Vec3& v, const Vec3& k, double a) {
  const double c = std::cos(a), s = std::sin(a);
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1 - c));
}

// A unit vector perpendicular to e.
Vec3 perpendicular(const Vec3& e) { return unit(std::abs(e.x) < 0.9 ? cross(e, Vec3(1, 0, 0)) : cross(e, Vec3(0, 1, 0))); }

// A branch waiting to be drawn: where it starts (a committed node), its heading and the
// turtle's up vector (turns are yaws about it), the heading of its parent at the bifurcation
// (a redraw turns the branch about it, keeping its angle), and its diameter.
struct Branch {
  std::int32_t from;
  Vec3 dir, up, parent_dir;
  double d;
};

class GrammarGrower {
 public:
  GrammarGrower(const GrammarOptions& o, GrammarReport& r)
      : o_(o),
        law_(o.murray_exponent, o.murray_band_edges, o.murray_band_exponents),
        r_(r),
        rng_(o.seed, o.sample, Stage::Growth),
        grid_(o.domain->lo(), o.domain->hi(), cellSize(o), o.domain->dimension() == 2) {}

  VascularTree run(const ProgressFn& progress) {
    t_.addNode(o_.root, -1);
    std::vector<Branch> gen{{0, unit(o_.direction), perpendicular(unit(o_.direction)), unit(o_.direction), *o_.root_diameter}};
    if (o_.domain->dimension() == 2) gen[0].up = Vec3(0, 0, 1);  // turns stay in the plane
    r_.asked_tips = std::int64_t(1) << o_.iterations;
    for (int g = 0; g <= o_.iterations; ++g) {
      std::vector<Branch> next;
      for (const auto& b : gen) {
        const auto end = drawStem(b);
        if (end < 0) continue;
        if (g == o_.iterations)
          ++r_.tips;  // a stem of the last generation ends in a tip
        else
          bifurcate(end, b.d, next);
      }
      gen.swap(next);
      if (progress) progress(g + 1, o_.iterations + 1);
    }
    return std::move(t_);
  }

 private:
  // Cells of about a piece of a middle generation (diameters fall by 2^(1/k) per generation).
  static double cellSize(const GrammarOptions& o) {
    const double d = *o.root_diameter * std::pow(2.0, -double(o.iterations) / (2 * o.murray_exponent));
    return std::max(1e-6, 2 * o.length_ratio * d / o.stem_segments);
  }

  double normal() { return rng_.normal(); }

  // Draws b's stem (again, in another plane, after a failure); returns its end node, or -1 when
  // every try left the domain or overlapped a vessel (the branch is dropped).
  std::int32_t drawStem(const Branch& b) {
    const double r = b.d / 2;
    bool outside = false;
    for (int attempt = 0; attempt < std::max(1, o_.tries); ++attempt) {
      Vec3 dir = b.dir, up = b.up;
      if (attempt > 0) {  // another plane about the parent's heading, same angle to it
        const double phi = 2 * std::numbers::pi * rng_.uniform();
        const Vec3 axis = o_.domain->dimension() == 2 ? Vec3(0, 0, 1) : b.parent_dir;
        if (o_.domain->dimension() == 2) {
          // In a plane the only other choice is the mirror image about the parent's heading.
          const double a = std::atan2(dot(cross(b.parent_dir, b.dir), axis), dot(b.parent_dir, b.dir));
          dir = rotate(b.parent_dir, axis, phi < std::numbers::pi ? -a : a);
        } else {
          dir = unit(rotate(b.dir, axis, phi));
          up = unit(rotate(b.up, axis, phi));
        }
        ++r_.redrawn;
      }
      const bool mirror = rng_.uniform() < 0.5;  // S1 or S2
      const double length = o_.length_ratio * b.d * rng_.uniform(1 - o_.length_margin, 1 + o_.length_margin);
      const double piece = length / o_.stem_segments;
      std::vector<Vec3> points{t_.position[std::size_t(b.from)]};
      bool ok = true;
      for (int i = 1; i <= o_.stem_segments && ok; ++i) {
        if (i > 1) {  // turns between pieces: + − − + … (mirrored in S2)
          const int k = (i - 1) % 4;
          const double sign = (k == 1 || k == 0 ? 1.0 : -1.0) * (mirror ? -1.0 : 1.0);
          dir = unit(rotate(dir, up, sign * o_.stem_angle * kDeg));
        }
        const Vec3 a = points.back(), e = a + dir * piece;
        if (!inside(a, e, r)) {
          ok = false;
          outside = true;
          break;
        }
        if (o_.avoid_collisions && collides(b.from, i, piece, a, e, r)) {
          ok = false;
          break;
        }
        points.push_back(e);
      }
      if (!ok) continue;
      std::int32_t prev = b.from;
      for (std::size_t i = 1; i < points.size(); ++i) {
        prev = t_.addNode(points[i], prev);
        t_.radius[prev] = r;
        grid_.insert(prev, points[i - 1], points[i], r);
      }
      last_dir_ = dir;
      last_up_ = up;
      return prev;
    }
    (outside ? r_.dropped_outside : r_.dropped_collision) += 1;
    return -1;
  }

  // The vessel a–e of radius r keeps `wall_clearance` from the wall and stays inside.
  bool inside(const Vec3& a, const Vec3& e, double r) const {
    const GrowthDomain& d = *o_.domain;
    if (d.depth(e) < r + o_.wall_clearance) return false;
    return d.shape() != DomainShape::Mask || d.frame().segmentClear(a, e);
  }

  // Piece `i` (from 1, each `piece` long) of a stem leaving node `from`, against the committed
  // vessels, except those joined to it along the tree by a path shorter than their radii (they
  // meet it at a joint): the overlap check reports the same pairs.
  bool collides(std::int32_t from, int i, double piece, const Vec3& a, const Vec3& e, double r) const {
    return grid_.any(a, e, r, [&](std::int32_t y) {
      const std::int32_t py = t_.parent[std::size_t(y)];
      // The path from `from` to segment y: 0 if y touches it, one segment's length if one lies between.
      double path = INFINITY;
      if (y == from || py == from)
        path = 0;
      else if (from > 0 && y == t_.parent[std::size_t(from)])
        path = t_.length[std::size_t(from)];
      else if (py >= 0 && t_.parent[std::size_t(py)] == from)
        path = t_.length[std::size_t(py)];
      else if (from > 0 && py == t_.parent[std::size_t(from)])
        path = t_.length[std::size_t(from)];
      const double ry = t_.radius[std::size_t(y)];
      if ((i - 1) * piece + path <= r + ry) return false;
      return capsulesOverlap(a, e, r, t_.position[std::size_t(py)], t_.position[std::size_t(y)], ry);
    });
  }

  // The two daughters of the stem just drawn (diameter d, ending at node `end`).
  void bifurcate(std::int32_t end, double d0, std::vector<Branch>& next) {
    const Branch b{end, last_dir_, last_up_, last_dir_, d0};
    const double k = law_.exponentAt(d0 / 2);
    double d1, d2, th1, th2;
    // No vessel thinner than the smallest radius a graph file holds: a vessel too thin to split
    // into two such daughters ends here, and the first daughter is held where both keep it.
    const double d_min = 2 * physical::kMinRadiusMm;
    if (o_.murray ? b.d < std::pow(2.0, 1.0 / k) * d_min : b.d * o_.radius_ratio < d_min) return;
    if (o_.murray) {
      const double opt = b.d / std::pow(2.0, 1.0 / k);
      d1 = o_.diameter_sd > 0 ? std::abs(opt + o_.diameter_sd * opt * normal()) : opt;
      if (!(d1 < b.d)) d1 = opt;
      d1 = std::clamp(d1, d_min, std::pow(std::pow(b.d, k) - std::pow(d_min, k), 1.0 / k));
      d2 = std::pow(std::pow(b.d, k) - std::pow(d1, k), 1.0 / k);
    } else {
      d1 = d2 = b.d * o_.radius_ratio;
    }
    if (o_.zamir_angles)
      zamirAngles(d1, d2, th1, th2);
    else
      th1 = th2 = o_.branch_angle * kDeg;
    th1 = std::clamp(th1 + o_.angle_sd * kDeg * normal(), 0.0, std::numbers::pi / 2);
    th2 = std::clamp(th2 + o_.angle_sd * kDeg * normal(), 0.0, std::numbers::pi / 2);
    const double roll = (o_.roll_angle + o_.roll_sd * normal()) * kDeg;
    const bool flat = o_.domain->dimension() == 2;
    for (int side = 0; side < 2; ++side) {
      const double th = side == 0 ? th1 : -th2;
      const Vec3 dir = unit(rotate(last_dir_, last_up_, th));
      // In 3D the daughter's frame rolls about its heading (its turns leave the parent's plane).
      const Vec3 up = flat ? last_up_ : unit(rotate(last_up_ - dir * dot(last_up_, dir), dir, roll));
      next.push_back({end, dir, up, last_dir_, side == 0 ? d1 : d2});
    }
  }

  const GrammarOptions& o_;
  MurrayLaw law_;
  GrammarReport& r_;
  Rng rng_;
  VascularTree t_;
  SegmentGrid grid_;         // committed segments
  Vec3 last_dir_, last_up_;  // the turtle at the end of the last stem drawn
};

}  // namespace

void zamirAngles(double d1, double d2, double& theta1, double& theta2) {
  const double a = d2 / d1, a3 = a * a * a, a4 = a3 * a, s = std::pow(1 + a3, 4.0 / 3);
  theta1 = std::acos(std::clamp((s + 1 - a4) / (2 * std::pow(1 + a3, 2.0 / 3)), -1.0, 1.0));
  theta2 = std::acos(std::clamp((s + a4 - 1) / (2 * a * a * std::pow(1 + a3, 2.0 / 3)), -1.0, 1.0));
}

VascularTree growGrammar(const GrammarOptions& o, GrammarReport& report, const ProgressFn& progress) {
  GrammarGrower g(o, report);
  VascularTree t = g.run(progress);
  const double need = o.min_tip_fraction * double(report.asked_tips);
  char fraction[32];
  std::snprintf(fraction, sizeof fraction, "%g", o.min_tip_fraction);
  if (double(report.tips) < need)
    throw GrowthError("the grammar grew " + std::to_string(report.tips) + " of the " + std::to_string(report.asked_tips) + " tips its " +
                      std::to_string(o.iterations) + " iterations ask for (" + std::to_string(report.dropped_outside) +
                      " branches left the domain, " + std::to_string(report.dropped_collision) +
                      " overlapped vessels in every try); at least min_tip_fraction = " + std::string(fraction) +
                      " of them must grow: enlarge the domain, lower root_diameter or length_ratio, or ask fewer iterations");
  return t;
}

}  // namespace angiosynth
