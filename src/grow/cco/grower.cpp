#include "grow/cco/grower.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "grow/common/bifurcation_optimizer.hpp"
#include "grow/common/connection_commit.hpp"
#include "grow/common/intersections.hpp"
#include "grow/common/kamiya.hpp"
#include "grow/common/segment_index.hpp"

namespace angiosynth {
namespace {

// ρ is recomputed exactly for the whole tree this often (O(N), so O(1) per terminal); between
// refreshes only the path of each new terminal is exact.
constexpr std::int64_t kRefreshEvery = 64;
// The final repair never removes more than this share of the terminals for one violation.
constexpr double kMaxRepairShare = 0.05;
// An ancestor is checked again for collisions once its radius has grown by this factor.
constexpr double kRecheckGrowth = 1.02;
// Segments with ρ at least this are "thick": checked from a list rather than through the grid.
constexpr double kThick = 0.25;

struct Trial {
  Connection c;
  bool kamiya_failed = false;
};

// The physics with CCO's cost, the total volume Σ π r² l (λ = 2, μ = 1).
PhysicsParameters volumePhysics(const CcoOptions& o) {
  PhysicsParameters p = o.physics;
  p.total_terminals = o.terminals;
  p.cost_radius_exponent = 2;
  p.cost_length_exponent = 1;
  return p;
}

class CcoGrower {
 public:
  CcoGrower(const GrowthDomain& d, const CcoOptions& o, GrowthReport& r)
      : dom_(d), opt_(o), report_(r), params_(volumePhysics(o)), kernel_(params_),
        index_(d.lo(), d.hi(), d.dimension() == 2), rng_(o.seed, o.sample, Stage::Growth) {
    tree_.reserve(2 * o.terminals + 1);
    tree_.addNode(o.root_mm, -1);
  }

  VascularTree run(const ProgressFn& progress) {
    growUntil(opt_.terminals, progress);
    repair(progress);
    report_.root_radius_mm = tree_.radius[tree_.rootSegment()];
    return std::move(tree_);
  }

 private:
  double scale(std::int64_t n) const { return std::pow(double(n) / double(opt_.terminals), 1.0 / dom_.dimension()); }
  // Root radius in final-domain units for n terminals and root reduced resistance R (final units):
  // physically r⁴ ∝ n·(s·R), and lengths shrink by s.
  double shrink(std::int64_t n) const { return std::pow(scale(n), -0.75); }
  double rootRadiusFinal(std::int64_t n, double R, double shrink_n) const {
    return rootRadius(params_, double(n) * params_.terminalFlow(), R) * shrink_n;
  }
  double currentRootRadius() const {
    const auto root = tree_.rootSegment();
    const auto n = tree_.terminals[root];
    return rootRadiusFinal(n, tree_.reduced_resistance[root], shrink(n));
  }
  bool startsAtRoot(std::int32_t seg) const { return tree_.parent[seg] == 0; }

  void plantFirst() {
    const Vec3 root = tree_.position[0];
    for (std::int64_t draws = 0; draws < opt_.max_draws; ++draws) {
      ++report_.candidates;
      const Vec3 p = dom_.sample(rng_);
      const double l = distance(root, p);
      const double r = rootRadiusFinal(1, l, shrink(1));
      if (!(l > 2 * r) || !dom_.capsuleInside(root, p, r, true)) {
        ++report_.rejected_unreachable;
        continue;
      }
      const auto t = tree_.addNode(p, 0);
      tree_.length[t] = l;
      tree_.terminals[t] = 1;
      tree_.reduced_resistance[t] = l;
      tree_.cost_ratio[t] = l;
      tree_.beta[t] = 1;
      rel_.assign(2, 1.0);
      index_.refresh(tree_, true);
      return;
    }
    throw GrowthError("no first terminal could be connected to the root: every segment from it leaves the domain "
                      "or is shorter than twice its radius; move the root inside the domain");
  }

  // Kamiya's bifurcation of segment s towards terminal p, with its volume and checks that need
  // no other vessel (run in parallel on a tree that does not change).
  Trial evaluate(std::int32_t s, const Vec3& p, std::int64_t n_new, double shrink_new, const BifurcationOptimizer& opt) const {
    Trial t;
    const auto& T = tree_;
    KamiyaProblem kp;
    kp.x0 = T.position[T.parent[s]];
    kp.x1 = T.position[s];
    kp.x2 = p;
    kp.f1 = T.terminals[s];
    kp.f2 = 1;
    kp.murray_exponent = params_.murray_exponent;
    const auto k = kamiyaBifurcation(kp, opt_.kamiya_iterations, opt_.kamiya_tolerance);
    if (!k.converged) {
      t.kamiya_failed = true;
      return t;
    }
    if (k.merged) return t;  // a zero-length segment
    Connection& c = t.c;
    c.segment = s;
    c.bifurcation = k.x;
    if (dom_.dimension() == 2) c.bifurcation.z = dom_.planeZ();  // in the plane to the last bit
    c.terminal = p;
    const double l[3] = {distance(kp.x0, k.x), distance(k.x, kp.x1), distance(k.x, p)};
    c.cost = opt.cost(s, l[0], l[1], l[2], &c.path);
    const auto& top = c.path.back();
    c.root_radius = rootRadius(params_, top.terminals * params_.terminalFlow(), top.reduced_resistance);
    // ρ of the new bifurcation segment: the product of β from the root down the recorded path.
    double rho_b = 1;
    for (std::size_t lv = 1; lv < c.path.size(); ++lv) rho_b *= c.path[lv].beta_child;
    const double rr = rootRadiusFinal(n_new, top.reduced_resistance, shrink_new);
    // Radii in final-domain units: new bifurcation segment, split part, terminal.
    const double r[3] = {rr * rho_b, rr * rho_b * c.path[0].beta_child, rr * rho_b * c.path[0].beta_other};
    for (int j = 0; j < 3; ++j)
      if (!(l[j] > 2 * r[j])) return t;  // §4.4: length / radius > 2
    if (!dom_.capsuleInside(kp.x0, k.x, r[0], startsAtRoot(s)) || !dom_.capsuleInside(k.x, kp.x1, r[1], false) ||
        !dom_.capsuleInside(k.x, p, r[2], false))
      return t;
    c.valid = true;
    return t;
  }

  // True if a segment touched by the committed connection overlaps a vessel more than one
  // segment away: the three new segments, and every ancestor (they all thicken) whose radius
  // has grown by more than kRecheckGrowth since it was last checked; the exact final check
  // covers that slack. Segments found clear are listed in cleared_.
  bool collides(const Connection& c, double rr) {
    const auto& T = tree_;
    const auto b = T.nodeCount() - 2;
    check_.assign({b, c.segment, b + 1});
    checked_.resize(T.nodeCount(), 0.0);
    for (std::size_t lv = 1; lv < c.path.size(); ++lv) {
      const auto x = c.path[lv].segment;
      if (rel_[x] * rr > kRecheckGrowth * checked_[x]) check_.push_back(x);
    }
    const auto radius_of = [&](std::int32_t y) { return rel_[y] * rr; };
    for (auto x : check_) {
      const Vec3& a0 = T.position[T.parent[x]];
      const Vec3& a1 = T.position[x];
      const double rx = rel_[x] * rr;
      // The grid is searched as far as thin vessels reach; the few thick ones are listed apart,
      // so the search does not widen with the root radius as the cells shrink.
      const auto candidates = [&](auto&& f) {
        index_.forEachNearSegment(a0, a1, rx + kThick * rr, f);
        const Vec3 mid = (a0 + a1) * 0.5;
        const double half = 0.5 * distance(a0, a1);
        for (auto y : thick_) {
          if (y >= T.nodeCount()) continue;
          const Vec3& b0 = T.position[T.parent[y]];
          const Vec3& b1 = T.position[y];
          if (distance(mid, (b0 + b1) * 0.5) <= half + 0.5 * distance(b0, b1) + rx + radius_of(y)) f(y);
        }
      };
      if (overlapsOtherVessel(T, x, a0, a1, rx, candidates, radius_of)) return true;
    }
    return false;
  }

  // ρ of the whole tree, and the list of thick segments.
  void refreshRelativeRadii() {
    refreshRelative(tree_, rel_);
    thick_.clear();
    for (std::int32_t s = 1; s < tree_.nodeCount(); ++s)
      if (rel_[s] >= kThick) thick_.push_back(s);
  }

  void markChecked(double rr) {
    for (auto x : check_) checked_[x] = rel_[x] * rr;
  }

  // Connects p through the cheapest valid bifurcation among its ν nearest segments, doubling ν
  // while none is valid. False when p lies in a vessel or no segment can take it.
  bool connect(const Vec3& p) {
    const std::int64_t n_new = tree_.terminalCount() + 1;
    const double rr_now = currentRootRadius(), shrink_new = shrink(n_new);
    const BifurcationOptimizer opt(tree_, params_, dom_.frame(), 0.0);
    int nu = opt_.closest_neighbours;
    std::size_t done = 0;
    for (;;) {
      index_.nearest(tree_, p, nu, near_);
      if (done == 0)
        for (const auto& [d, id] : near_)
          if (d <= rel_[id] * rr_now) return false;  // inside a vessel (Algorithm 2)
      trials_.resize(near_.size());
      // Two halves: finer tasks cost more in scheduling than the few microseconds each takes.
      const std::size_t grain = std::max<std::size_t>(1, (near_.size() - done + 1) / 2);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(done, near_.size(), grain), [&](const auto& r) {
        for (auto i = r.begin(); i != r.end(); ++i) trials_[i] = evaluate(near_[i].second, p, n_new, shrink_new, opt);
      }, tbb::simple_partitioner());
      order_.clear();
      for (std::size_t i = done; i < near_.size(); ++i) {
        if (trials_[i].kamiya_failed) ++report_.kamiya_failures;
        if (trials_[i].c.valid) order_.push_back(i);
      }
      std::sort(order_.begin(), order_.end(), [&](auto a, auto b) {
        return std::tie(trials_[a].c.cost, trials_[a].c.segment) < std::tie(trials_[b].c.cost, trials_[b].c.segment);
      });
      for (auto i : order_) {
        const Connection& c = trials_[i].c;
        const auto undo = commitConnection(tree_, c, opt, kernel_, rel_);
        const double rr = rootRadiusFinal(n_new, c.path.back().reduced_resistance, shrink_new);
        if (!collides(c, rr)) {
          markChecked(rr);
          const auto n = tree_.nodeCount();
          index_.insert(tree_, n - 2);
          index_.insert(tree_, n - 1);
          index_.insert(tree_, c.segment);
          index_.refresh(tree_);
          if (rel_[n - 2] >= kThick) thick_.push_back(n - 2);
          if (tree_.terminalCount() % kRefreshEvery == 0) refreshRelativeRadii();
          return true;
        }
        rollbackConnection(tree_, undo, rel_);
        ++report_.rejected_intersection;
      }
      done = near_.size();
      if (static_cast<std::int32_t>(done) >= tree_.segmentCount() || nu >= opt_.max_neighbours) return false;
      nu = std::min(2 * nu, opt_.max_neighbours);
      ++report_.neighbour_doublings;
    }
  }

  void growUntil(std::int64_t target, const ProgressFn& progress) {
    std::int64_t next_report = 0;
    while (tree_.terminalCount() < target) {
      if (progress && tree_.terminalCount() >= next_report) {
        progress(tree_.terminalCount(), target);
        next_report = tree_.terminalCount() + std::max<std::int64_t>(1, target / 200);
      }
      if (tree_.segmentCount() == 0) {
        plantFirst();
        continue;
      }
      // δ_max (seed 000 eq. 15) for the current number of terminals, relaxed by runs of failures.
      double delta = std::pow(dom_.measure() / double(tree_.terminalCount()), 1.0 / dom_.dimension());
      for (std::int64_t failures = 1;; ++failures) {
        if (failures > opt_.max_draws)
          throw GrowthError("could place only " + std::to_string(tree_.terminalCount()) + " of " + std::to_string(target) +
                            " terminals: " + std::to_string(opt_.max_draws) + " points in a row found no valid connection "
                            "(too close " + std::to_string(report_.rejected_too_close) + ", unconnectable " +
                            std::to_string(report_.rejected_unreachable) + "); lower the number of terminals or enlarge the domain");
        const Vec3 p = dom_.sample(rng_);
        if (index_.anyWithin(tree_, p, delta * dom_.spacingScale(p))) {
          ++report_.rejected_too_close;
        } else {
          ++report_.candidates;
          if (connect(p)) break;
          ++report_.rejected_unreachable;
        }
        if (failures % opt_.draws_before_relaxing == 0) {
          delta *= opt_.relaxation;
          ++report_.threshold_relaxations;
        }
      }
    }
    if (progress) progress(tree_.terminalCount(), target);
  }

  // True if the solved tree's segment x, with ends a–e, stays in the domain, longer than twice
  // its radius and clear of every vessel more than one segment away (radii with 2 % margin).
  bool segmentFits(std::int32_t x, const Vec3& a, const Vec3& e) {
    const auto& T = tree_;
    const double rx = 1.02 * T.radius[x];
    if (!(distance(a, e) > 2 * rx) || !dom_.capsuleInside(a, e, rx, startsAtRoot(x))) return false;
    const double reach = rx + 1.02 * T.radius[T.rootSegment()];
    return !overlapsOtherVessel(
        T, x, a, e, rx, [&](auto&& f) { index_.forEachNearSegment(a, e, reach, f); },
        [&](std::int32_t y) { return 1.02 * T.radius[y]; });
  }

  // Moves node v to q if every segment meeting there still fits; restores it otherwise.
  bool tryMove(std::int32_t v, const Vec3& q) {
    auto& T = tree_;
    const Vec3 old = T.position[v];
    T.position[v] = q;
    const std::int32_t segs[3] = {v, T.child0[v], T.child1[v]};
    bool ok = true;
    for (auto x : segs)
      if (x > 0 && ok) ok = segmentFits(x, T.position[T.parent[x]], T.position[x]);
    if (!ok) {
      T.position[v] = old;
      return false;
    }
    for (auto x : segs)
      if (x > 0) index_.insert(T, x);
    return true;
  }

  // A trunk that thickened past half its length since it was made: slide its distal
  // bifurcation outwards (along the trunk, or towards its children), or its proximal one back,
  // to 2.1–3 r, whichever first fits.
  bool lengthen(std::int32_t s) {
    auto& T = tree_;
    const auto P = T.parent[s];
    const Vec3 a = T.position[P], e = T.position[s];
    const Vec3 u = (e - a) / distance(a, e);
    Vec3 w = u;
    if (!T.isTerminal(s)) {
      const Vec3 m = (T.position[T.child0[s]] + T.position[T.child1[s]]) * 0.5 - e;
      if (norm(m) > 0) w = m / norm(m);
    }
    for (double f : {2.1, 2.5, 3.0}) {
      const double L = f * T.radius[s], grow = L - distance(a, e);
      if (!T.isTerminal(s) && (tryMove(s, a + u * L) || tryMove(s, e + w * grow))) return true;
      if (P > 0 && tryMove(P, e - u * L)) return true;
    }
    return false;
  }

  // A segment that the solved radii push out of the domain (its subtree too large to regrow):
  // move its distal node, else its proximal one, up the depth gradient by 0.5–3 r, whichever
  // first fits. Seen only where the final solve thickened a trunk next to a thin mask wall.
  bool pushInside(std::int32_t s) {
    auto& T = tree_;
    const double h = dom_.frame().voxel_mm;
    for (const std::int32_t v : {s, T.parent[s]}) {
      if (v <= 0) continue;
      const Vec3 p = T.position[v];
      Vec3 g(dom_.depth(p + Vec3(h, 0, 0)) - dom_.depth(p - Vec3(h, 0, 0)),
             dom_.depth(p + Vec3(0, h, 0)) - dom_.depth(p - Vec3(0, h, 0)),
             dom_.dimension() == 2 ? 0.0 : dom_.depth(p + Vec3(0, 0, h)) - dom_.depth(p - Vec3(0, 0, h)));
      if (!(norm(g) > 0)) continue;
      g = g / norm(g);
      for (double f : {0.5, 1.0, 2.0, 3.0})
        if (tryMove(v, p + g * (f * T.radius[s]))) return true;
    }
    return false;
  }

  // Segments of the solved tree that break a constraint: intersecting pairs, length <= 2r, or
  // leaving the domain. Short trunks are lengthened in place; for the rest, the segment whose
  // subtree removal costs fewest terminals is returned.
  std::vector<std::int32_t> violations() {
    const auto& T = tree_;
    std::vector<std::int32_t> out;
    const auto pairs = intersectingPairs(T, dom_.lo(), dom_.hi());
    report_.intersecting_pairs = static_cast<std::int64_t>(pairs.size());
    for (const auto& [x, y] : pairs) out.push_back(std::tie(T.terminals[x], y) < std::tie(T.terminals[y], x) ? x : y);
    report_.short_segments = report_.outside_segments = 0;
    index_.refresh(tree_, true);
    for (std::int32_t s = 1; s < T.nodeCount(); ++s) {
      if (!(T.length[s] > 2 * T.radius[s])) {
        ++report_.short_segments;
        if (lengthen(s)) {
          ++report_.moved_nodes;
        } else if (T.isTerminal(s)) {
          out.push_back(s);
        } else {  // the trunk merges with its larger child when the smaller child's subtree goes
          out.push_back(T.terminals[T.child0[s]] <= T.terminals[T.child1[s]] ? T.child0[s] : T.child1[s]);
        }
      }
      if (!dom_.capsuleInside(T.position[T.parent[s]], T.position[s], T.radius[s], startsAtRoot(s))) {
        ++report_.outside_segments;
        if (T.terminals[s] > kMaxRepairShare * double(opt_.terminals) && pushInside(s)) ++report_.moved_nodes;
        else out.push_back(s);
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  // Solves the exact final tree; removes and regrows the branches that break a constraint.
  void repair(const ProgressFn& progress) {
    for (int round = 0;; ++round) {
      solveTree(tree_, params_);
      const auto moved_before = report_.moved_nodes;
      auto bad = violations();
      std::erase_if(bad, [&](std::int32_t s) { return tree_.terminals[s] > kMaxRepairShare * double(opt_.terminals); });
      const bool moved = report_.moved_nodes > moved_before;
      if ((bad.empty() && !moved) || round == opt_.max_repair_rounds) return;
      ++report_.repair_rounds;
      if (!bad.empty()) {
        const auto before = tree_.terminalCount();
        tree_.removeSubtrees(bad);
        report_.repaired_terminals += before - tree_.terminalCount();
      }
      solveTree(tree_, params_);
      refreshRelativeRadii();
      checked_ = tree_.radius;  // the exact check just passed every kept segment
      index_.refresh(tree_, true);
      growUntil(opt_.terminals, progress);
    }
  }

  const GrowthDomain& dom_;
  const CcoOptions& opt_;
  GrowthReport& report_;
  PhysicsParameters params_;
  PowerKernel kernel_;
  SegmentIndex index_;
  Rng rng_;
  VascularTree tree_;
  std::vector<double> rel_{1.0};  // ρ: radius / root radius
  std::vector<std::pair<double, std::int32_t>> near_;
  std::vector<Trial> trials_;
  std::vector<std::size_t> order_;
  std::vector<std::int32_t> check_;
  std::vector<double> checked_;         // radius (final units) at which each segment was last found clear
  std::vector<std::int32_t> thick_{1};  // segments with ρ >= kThick (the first is the root segment)
};

}  // namespace

VascularTree growCco(const GrowthDomain& domain, const CcoOptions& options, GrowthReport& report,
                     const ProgressFn& progress) {
  CcoGrower g(domain, options, report);
  return g.run(progress);
}

}  // namespace angiosynth
