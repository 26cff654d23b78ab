#include "grow/cco/grower.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <tuple>

#include "grow/common/bifurcation_optimizer.hpp"
#include "grow/common/connection_commit.hpp"
#include "grow/common/intersections.hpp"
#include "grow/common/kamiya.hpp"
#include "grow/common/spread_bifurcation.hpp"
#include "core/point_hash.hpp"
#include "core/segment_index.hpp"

namespace angiosynth {
namespace {

// ρ is recomputed exactly for the whole tree this often (O(N), so O(1) per terminal); between
// refreshes only the path of each new terminal is exact.
constexpr std::int64_t kRefreshEvery = 64;
// At organ scale the relative radii are refreshed once the tree has grown by 1/kOrganRefreshShare.
constexpr std::int64_t kOrganRefreshShare = 256;
// The final repair never removes more than this share of the terminals for one violation.
constexpr double kMaxRepairShare = 0.05;
// For a trunk shorter than 2r that no move can lengthen, the side branch it merges with its
// larger child by losing may be larger (rare: docs/benchmarks.md, "Figures behind design choices").
constexpr double kMaxShortRepairShare = 0.15;
// Vessels in the way of a short trunk's lengthening, with at most this many terminals, are
// removed and regrown rather than leave the trunk short; in a single tree's growth, an ancestor
// that keeps hitting such a vessel stops counting it (the final repair regrows it)...
constexpr std::int32_t kMaxClearedTerminals = 8;
// ... or, beside a trunk, vessels with at most 1/kSmallBeside of its terminals.
constexpr std::int32_t kSmallBeside = 64;
// An ancestor is checked again for collisions once its radius has grown by this factor.
constexpr double kRecheckGrowth = 1.02;
// Connections refused in a row (for one terminal) because an ancestor hit another tree, after
// which a forest's ancestors skip that check.
constexpr std::int64_t kLenientAfter = 100;
// Refusals caused by one ancestor hitting a vessel, after which the vessels the final repair
// may regrow no longer block it (see `counts`).
constexpr std::uint8_t kDeferAfter = 8;
// A vessel whose surface lies within this fraction of the last connected terminal's radius from
// a drawn point crowds out the connections whose terminal segment it would touch (crowdedOut).
// Half the radius, as a new terminal is rarely thinner than half the last one; a larger fraction
// crowds out connections that would have fitted and makes trees heavier (docs/benchmarks.md,
// "Why the CCO grower's constants are what they are").
constexpr double kCrowdedTerminal = 0.5;
// Nearest segments that first test whether a drawn point lies inside a vessel.
constexpr int kInsideProbe = 4;
// Segments with ρ at least this are "thick": checked from a list rather than through the grid.
constexpr double kThick = 0.25;

// Nearest segments that may hide a farther one from a drawn point in the plane: beyond about 40
// more of them hide hardly any further trial (docs/benchmarks.md, as above).
constexpr std::size_t kOccluders = 40;

// True if segment y is within two segments of the terminal segment of a connection that splits
// s (withinTwoSegments once committed): y is s, its parent, its sibling or a child.
bool besideSplit(const VascularTree& T, std::int32_t s, std::int32_t y) {
  return y == s || y == T.parent[s] || T.parent[y] == T.parent[s] || T.parent[y] == s;
}

// True if, in the plane, c's terminal segment crosses the centreline of a segment in `near` that
// has no end at either end of the segment it splits: the collision check would refuse it
// (whatever the radii), and with no other effect, since the new segments come before the
// ancestors there.
bool terminalCrossesInPlane(const VascularTree& T, const Connection& c, const std::vector<std::pair<double, std::int32_t>>& near) {
  const std::int32_t s = c.segment;
  for (const auto& [d, y] : near) {
    if (besideSplit(T, s, y)) continue;
    if (crossInPlane(c.bifurcation, c.terminal, T.position[T.parent[y]], T.position[y])) return true;
  }
  return false;
}

// Kamiya's connection and the exact volume optimiser's, each valid or not: the exact one is
// lighter but may collide where Kamiya's does not.
struct Trial {
  Connection c[2];
  bool kamiya_failed = false;
  bool merged_at_parent = false;     // Kamiya's optimum is the split segment's proximal node
  bool at_node = false;              // and the exact one too: not refined
  bool hidden = false;               // not tried: a vessel separates it from the point (separatedInPlane)
  bool crowded = false;              // not tried: the new terminal's vessel would overlap one near the point
  bool crosses[2] = {false, false};  // c[i]'s terminal segment crosses a vessel (terminalCrossesInPlane)
};

// The physics with CCO's cost, the total volume Σ π r² l (λ = 2, μ = 1).
PhysicsParameters volumePhysics(const CcoOptions& o) {
  PhysicsParameters p = o.physics;
  p.total_terminals = o.terminals;
  p.cost_radius_exponent = 2;
  p.cost_length_exponent = 1;
  return p;
}

// One tree of the forest and what its growth keeps beside it.
struct TreeGrowth {
  TreeGrowth(const GrowthDomain& d, PhysicsParameters p, const Vec3& root, int system_id, std::int64_t reserve)
      : params(p), kernel(params), index(d.lo(), d.hi(), d.dimension() == 2), system(system_id) {
    tree.reserve(2 * reserve + 1);
    tree.addNode(root, -1);
  }
  PhysicsParameters params;
  PowerKernel kernel;
  SegmentIndex index;
  int system;
  std::int64_t quota = 0;  // fixed number of terminals; 0: the territory it wins
  VascularTree tree;
  std::vector<double> rel{1.0};            // ρ: radius / root radius
  std::vector<double> checked;             // radius (final units) at which each segment was last found clear
  std::vector<std::uint8_t> blocks;        // connections each segment refused, as an ancestor, by hitting a vessel
  std::array<std::int32_t, 4> blockers{};  // the last ancestors that refused a connection (0: none)
  std::uint32_t next_blocker = 0;
  std::vector<std::int32_t> thick{1};  // segments with ρ >= kThick (the first is the root segment)
  std::vector<std::pair<double, std::int32_t>> near;
  std::vector<std::int32_t> crowding;  // segments whose vessel comes within a terminal's radius of the point
  double terminal_radius = 0;          // radius (final units) of the last terminal connected
  std::size_t done = 0;                // near[0, done) evaluated in earlier rounds
  // Terminal points for the spacing test of draws, in cells of δ when built; rebuilt when the
  // terminals double (δ shrinks) and after a repair (nodes renumbered and moved).
  std::unique_ptr<PointHash> terminal_grid;
  std::int32_t grid_nodes = 0;    // nodes [0, grid_nodes) are in the grid
  std::int64_t grid_built = 0;    // terminals when it was built
  std::int64_t next_refresh = 0;  // terminals at the next refresh of the relative radii
  std::int32_t terminalCount() const { return tree.terminalCount(); }
};

// Inlets competing for the same terminals (one kind).
struct System {
  std::int64_t target = 0;
  std::int64_t territory = 0;  // terminals for the inlets without a fixed share
  std::vector<int> trees;
};

// Quasi-Newton steps of the exact optimiser from Kamiya's point. Kamiya's radii come from his
// law, not from the tree, so his point is off the tree's optimum; the first steps recover most
// of the difference, and more steps do not make lighter trees (docs/benchmarks.md, as above).
constexpr int kRefineIterations = 4;
// The exact point counts only inside l > 2.1 r: an optimum pressed against l = 2r crowds its
// neighbours, and as they thicken their ancestors collide and refuse every later connection
// below them, and growth slows by orders of magnitude.
constexpr double kInteriorMargin = 1.05;
constexpr double kRootMargin = 1.25;
constexpr std::size_t kRefineNearest = 8;
// At organ scale: how many of Kamiya's valid points (the lightest) and of the nearest segments
// without one are refined.
constexpr std::size_t kOrganRefined = 4;

// A trial connection of a drawn point to one tree, ranked by the volume it adds to the forest.
struct Candidate {
  int tree;
  std::size_t trial;
  int which;  // Trial::c index
  double added;
};

class CcoGrower {
 public:
  CcoGrower(const GrowthDomain& d, const CcoOptions& o, const std::vector<CcoInlet>& inlets, GrowthReport& r)
      : dom_(d), opt_(o), report_(r), rng_(o.seed, o.sample, Stage::Growth) {
    int systems = 0;
    for (const auto& in : inlets) systems = std::max(systems, in.system + 1);
    systems_.resize(systems);
    relaxed_.assign(std::size_t(systems), 0.0);
    for (std::size_t k = 0; k < inlets.size(); ++k) {
      const auto& in = inlets[k];
      trees_.emplace_back(d, inletPhysics(volumePhysics(o), in.root_pressure, in.terminal_pressure), in.root_mm, in.system, o.terminals);
      systems_[in.system].trees.push_back(int(k));
    }
    for (auto& sys : systems_) {
      sys.target = o.terminals;
      std::vector<double> shares;
      for (int k : sys.trees) shares.push_back(inlets[k].share);
      const auto quotas = terminalQuotas(shares, sys.target);
      sys.territory = sys.target;
      for (std::size_t i = 0; i < sys.trees.size(); ++i) {
        trees_[sys.trees[i]].quota = quotas[i];
        sys.territory -= quotas[i];
      }
    }
  }

  std::vector<VascularTree> run(const ProgressFn& progress) {
    growUntilTargets(progress);
    repair(progress);
    report_.root_radius_mm = trees_[0].tree.radius[trees_[0].tree.rootSegment()];
    report_.short_list.clear();
    for (std::size_t k = 0; k < trees_.size(); ++k) {
      const auto& T = trees_[k].tree;
      for (std::int32_t s = 1; s < T.nodeCount(); ++s)
        if (!(T.length[s] > 2 * T.radius[s])) {
          const Vec3 a = T.position[T.parent[s]], e = T.position[s];
          report_.short_list.push_back({int(k), {a.x, a.y, a.z}, {e.x, e.y, e.z}, T.length[s], T.radius[s]});
        }
    }
    report_.short_segments = static_cast<std::int64_t>(report_.short_list.size());
    std::vector<VascularTree> out;
    for (auto& t : trees_) out.push_back(std::move(t.tree));
    return out;
  }

 private:
  std::int64_t systemTerminals(const System& s) const {
    std::int64_t n = 0;
    for (int k : s.trees) n += trees_[k].terminalCount();
    return n;
  }
  // The domain grows with each system: s = (n/N)^(1/d) for the n terminals it has.
  double scale(const System& s, std::int64_t n) const { return std::pow(double(n) / double(s.target), 1.0 / dom_.dimension()); }
  // Root radius in final-domain units for n terminals and root reduced resistance R (final units):
  // physically r⁴ ∝ n·(s·R), and lengths shrink by s.
  // Regrowth after the final repair fills holes in the final domain: in a forest it keeps the
  // final scale, since the inflated radii of a domain that is "still growing" would make every
  // trunk collide with the other tree's vessels beside it. (A single tree keeps the scaling.)
  double shrink(const System& s, std::int64_t n) const { return repairing_ && trees_.size() > 1 ? 1.0 : std::pow(scale(s, n), -0.75); }
  static double rootRadiusFinal(const TreeGrowth& g, std::int64_t n, double R, double shrink_n) {
    return rootRadius(g.params, double(n) * g.params.terminalFlow(), R) * shrink_n;
  }
  double currentRootRadius(const TreeGrowth& g) const {
    const auto root = g.tree.rootSegment();
    if (root < 0) return 0;
    const auto& sys = systems_[g.system];
    return rootRadiusFinal(g, g.tree.terminals[root], g.tree.reduced_resistance[root], shrink(sys, systemTerminals(sys)));
  }
  static bool startsAtRoot(const TreeGrowth& g, std::int32_t seg) { return g.tree.parent[seg] == 0; }
  // True if tree k may take one more terminal.
  bool accepts(int k) const {
    const auto& g = trees_[k];
    if (g.quota > 0) return g.terminalCount() < g.quota;
    std::int64_t n = 0;
    for (int j : systems_[g.system].trees)
      if (trees_[j].quota == 0) n += trees_[j].terminalCount();
    return n < systems_[g.system].territory;
  }

  // Calls f(y) for the segments of g that may overlap the capsule a–e of radius r: the grid as
  // far as thin vessels (ρ < kThick) reach, and the few thick ones from their list, so the search
  // does not widen with the root radius rr as the cells shrink.
  template <class Radius, class F>
  static void forEachNearVessel(TreeGrowth& g, const Vec3& a, const Vec3& e, double r, double rr, Radius&& radius_of, F&& f) {
    const auto& T = g.tree;
    g.index.forEachNearSegment(a, e, r + kThick * rr, f);
    const Vec3 mid = (a + e) * 0.5;
    const double half = 0.5 * distance(a, e);
    for (auto y : g.thick) {
      if (y >= T.nodeCount()) continue;
      const Vec3& b0 = T.position[T.parent[y]];
      const Vec3& b1 = T.position[y];
      if (distance(mid, (b0 + b1) * 0.5) <= half + 0.5 * distance(b0, b1) + r + radius_of(y)) f(y);
    }
  }

  // True if the capsule a–e of radius r overlaps a vessel of a tree other than k: with the radii
  // of growth (ρ × the current root radius), or, on the solved forest, the exact radii + 2 %.
  // With big_only, only vessels too large for the final repair to regrow count.
  bool hitsOtherTree(int k, const Vec3& a, const Vec3& e, double r, bool solved = false, bool big_only = false) {
    for (std::size_t j = 0; j < trees_.size(); ++j) {
      if (int(j) == k) continue;
      auto& o = trees_[j];
      if (o.tree.segmentCount() == 0) continue;
      // During growth both sides carry the slack of kRecheckGrowth, and the other vessel counts
      // with the radius it was last checked at if that is larger: a vessel is checked again only
      // once it has thickened past that by kRecheckGrowth, so the pair stays clear until one of
      // them is checked again. (Trunks of two trees that start side by side are too large for
      // the final repair to regrow.)
      const double rr = solved ? 1.02 * o.tree.radius[o.tree.rootSegment()] : kRecheckGrowth * currentRootRadius(o);
      const auto radius_of = [&](std::int32_t y) {
        if (solved) return 1.02 * o.tree.radius[y];
        const double last = y < std::int32_t(o.checked.size()) ? o.checked[y] : 0.0;
        return std::max(o.rel[y] * rr, kRecheckGrowth * last);
      };
      bool hit = false;
      const auto test = [&](std::int32_t y) {
        if (hit || y >= o.tree.nodeCount() || y < 1 || (big_only && !tooLargeToRegrow(int(j), y))) return;
        hit = capsulesOverlap(a, e, r, o.tree.position[o.tree.parent[y]], o.tree.position[y], radius_of(y));
      };
      if (solved) {  // the index holds the final geometry; the thickest vessel bounds the reach
        o.index.forEachNearSegment(a, e, r + rr, test);
        if (hit) return true;
        continue;
      }
      forEachNearVessel(o, a, e, r, rr, radius_of, test);
      if (hit) return true;
    }
    return false;
  }

  // A point drawn in the domain, at least terminal_depth deep.
  Vec3 drawPoint() {
    for (;;) {
      const Vec3 p = dom_.sample(rng_);
      if (!(opt_.terminal_depth > 0) || dom_.depth(p) >= opt_.terminal_depth) return p;
    }
  }

  void plantFirst(int k) {
    auto& g = trees_[k];
    const auto& sys = systems_[g.system];
    const Vec3 root = g.tree.position[0];
    const double shrink_new = shrink(sys, systemTerminals(sys) + 1);
    for (std::int64_t draws = 0; draws < opt_.max_draws; ++draws) {
      ++report_.candidates;
      const Vec3 p = drawPoint();
      const double l = distance(root, p);
      const double r = rootRadiusFinal(g, 1, l, shrink_new);
      if (!(l > 2 * r) || !dom_.capsuleInside(root, p, r, true) || hitsOtherTree(k, root, p, kRecheckGrowth * r)) {
        ++report_.rejected_unreachable;
        continue;
      }
      const auto t = g.tree.addNode(p, 0);
      g.tree.length[t] = l;
      g.tree.terminals[t] = 1;
      g.tree.reduced_resistance[t] = l;
      g.tree.cost_ratio[t] = l;
      g.tree.beta[t] = 1;
      g.rel.assign(2, 1.0);
      g.index.refresh(g.tree, true);
      return;
    }
    throw GrowthError("no first terminal could be connected to the root" +
                      std::string(trees_.size() > 1 ? " of inlet " + std::to_string(k + 1) : "") +
                      ": every segment from it leaves the domain, is shorter than twice its radius" +
                      (trees_.size() > 1 ? " or crosses another tree" : "") + "; move the root inside the domain");
  }

  // The bifurcations of segment s towards terminal p, with their volume and the checks that need
  // no other vessel (run in parallel on a tree that does not change): Kamiya's fixed point, and
  // with BifurcationPoint::Exact the exact minimum of the tree's volume near it. Both are ranked:
  // where the lighter one collides, the other may not.
  Trial evaluate(const TreeGrowth& g, std::int32_t s, const Vec3& p, std::int64_t n_new, double shrink_new, const BifurcationOptimizer& opt) const {
    Trial t;
    const auto& T = g.tree;
    KamiyaProblem kp;
    kp.x0 = T.position[T.parent[s]];
    kp.x1 = T.position[s];
    kp.x2 = p;
    kp.f1 = T.terminals[s];
    kp.f2 = 1;
    kp.murray_exponent = g.params.murray_exponent;
    const auto k = kamiyaBifurcation(kp, opt_.kamiya_iterations, opt_.kamiya_tolerance);
    t.kamiya_failed = !k.converged;
    t.merged_at_parent = k.merged && k.x == kp.x0;
    if (k.converged && !k.merged) {  // merged: a zero-length segment
      Connection& c = t.c[0];
      c.segment = s;
      c.bifurcation = k.x;
      c.terminal = p;
      fits(g, c, n_new, shrink_new, opt);
    }
    return t;
  }

  // The exact minimum of the tree's volume for segment s and terminal p, started from Kamiya's
  // point k where he found one; valid only where lighter than a valid k, and inside the margin.
  Connection refine(const TreeGrowth& g, const Connection& k, std::int32_t s, const Vec3& p, std::int64_t n_new, double shrink_new,
                    const BifurcationOptimizer& opt) const {
    Connection o = opt.optimise(s, p, kRefineIterations, k.segment >= 0 ? &k.bifurcation : nullptr);
    if (!o.valid) return o;
    o.valid = false;
    if (fits(g, o, n_new, shrink_new, opt, kInteriorMargin) && k.valid && !(o.cost < k.cost)) o.valid = false;
    return o;
  }

  // Sets c's cost at its bifurcation, and c.valid if its three segments are longer than twice
  // their radii (in final-domain units) and inside the domain. Its path is recorded only if it is
  // committed (in connect).
  bool fits(const TreeGrowth& g, Connection& c, std::int64_t n_new, double shrink_new, const BifurcationOptimizer& opt, double margin = 1) const {
    const auto& T = g.tree;
    if (dom_.dimension() == 2) c.bifurcation.z = dom_.planeZ();  // in the plane to the last bit
    const Vec3 x0 = T.position[T.parent[c.segment]], x1 = T.position[c.segment], b = c.bifurcation;
    const double l[3] = {distance(x0, b), distance(b, x1), distance(b, c.terminal)};
    const auto sum = opt.summarise(c.segment, l[0], l[1], l[2]);
    c.cost = sum.cost;
    // ρ of the new bifurcation segment: the product of β from the root down the path.
    const double rho_b = sum.beta_down;
    const double rr = rootRadiusFinal(g, n_new, sum.reduced_resistance, shrink_new);
    // Radii in final-domain units: new bifurcation segment, split part, terminal.
    const double r[3] = {rr * rho_b, rr * rho_b * sum.beta_child, rr * rho_b * sum.beta_other};
    // The root segment gets kRootMargin more: its proximal end is fixed, so the final check
    // cannot lengthen it when the solved root comes out thicker than its mapped radius.
    const double root_margin = startsAtRoot(g, c.segment) ? kRootMargin : 1.0;
    for (int j = 0; j < 3; ++j)
      if (!(l[j] > 2 * margin * (j == 0 ? root_margin : 1.0) * r[j])) return false;  // §4.4: length / radius > 2
    if (!dom_.capsuleInside(x0, b, r[0], startsAtRoot(g, c.segment)) || !dom_.capsuleInside(b, x1, r[1], false) ||
        !dom_.capsuleInside(b, c.terminal, r[2], false))
      return false;
    c.valid = true;
    return true;
  }

  // True if a segment of tree k touched by the committed connection overlaps a vessel more than
  // one segment away, or one of another tree: the three new segments, and every ancestor (they
  // all thicken) whose radius has grown by more than kRecheckGrowth since it was last checked;
  // the exact final check covers that slack. Segments found clear are listed in check_.
  bool collides(int k, const Connection& c, double rr) {
    auto& g = trees_[k];
    const auto& T = g.tree;
    const auto b = T.nodeCount() - 2;
    check_.assign({b, c.segment, b + 1});
    g.checked.resize(T.nodeCount(), 0.0);
    g.blocks.resize(T.nodeCount(), 0);
    skipped_ = false;
    for (std::size_t lv = 1; lv < c.path.size(); ++lv) {
      const auto x = c.path[lv].segment;
      if (g.rel[x] * rr > kRecheckGrowth * g.checked[x]) check_.push_back(x);
    }
    const auto radius_of = [&](std::int32_t y) { return g.rel[y] * rr; };
    const bool forest = trees_.size() > 1;
    // An ancestor that refused a recent connection by a collision usually refuses the next one
    // below it too (a subtree beside a vessel it has thickened into): in a single tree, whose
    // check only answers yes or no, it is checked first, and the refusal counts as its own.
    if (!forest && !repairing_)
      for (const auto x : g.blockers)
        if (x > 0 && std::find(check_.begin() + 3, check_.end(), x) != check_.end() &&
            overlapsOwnTree(g, x, rr, radius_of, [&](std::int32_t y) { return counts(k, x, y, true); })) {
          countRefusal(g, x);
          return true;
        }
    for (const auto& x : check_) {
      const Vec3& a0 = T.position[T.parent[x]];
      const Vec3& a1 = T.position[x];
      const double rx = g.rel[x] * rr;
      // In a forest, an ancestor that keeps hitting a vessel would freeze its whole subtree (every
      // connection below it thickens it; seen for a vein's root segment beside a branch of its
      // own): after kDeferAfter refusals only vessels too large to regrow still block it (the
      // final check finds the others, and the repair regrows them), and after a long run of
      // failures no other tree's vessel does. A single tree does so while the repair regrows:
      // the holes it fills lie beside the trunks that made them, and without this a regrowth can
      // place nothing for minutes; while it grows, only vessels of a few terminals stop counting.
      const bool ancestor = &x - check_.data() >= 3;
      const bool defer = forest || repairing_;
      const bool big_only = defer && ancestor && g.blocks[x] >= kDeferAfter;
      bool hit = overlapsOwnTree(g, x, rr, radius_of, [&](std::int32_t y) { return counts(k, x, y, ancestor); });
      if (!hit && forest) {
        if (ancestor && lenient_) {
          skipped_ = true;
          continue;
        }
        hit = hitsOtherTree(k, a0, a1, kRecheckGrowth * rx, false, big_only);
        ancestor_blocks_ += hit && ancestor;
      }
      skipped_ |= big_only;
      if (hit) {
        if (ancestor) countRefusal(g, x);
        return true;
      }
    }
    return false;
  }

  // Whether vessel y of tree k blocks segment x of a committed connection. An ancestor that has
  // refused kDeferAfter connections stops counting the vessels the final repair may regrow: in a
  // forest, or while the repair regrows, those up to kMaxRepairShare of the terminals; in a
  // single tree's growth, those of at most kMaxClearedTerminals terminals or 1/kSmallBeside of
  // its own: a trunk that thickened into a small branch below it would otherwise refuse millions
  // of connections, and clearing any vessel of a few dozen terminals regrows too many
  // (docs/benchmarks.md, as above).
  bool counts(int k, std::int32_t x, std::int32_t y, bool ancestor) const {
    const auto& g = trees_[k];
    if (!ancestor || y >= g.tree.nodeCount() || g.blocks[x] < kDeferAfter) return true;
    if (trees_.size() > 1 || repairing_) return tooLargeToRegrow(k, y);
    return g.tree.terminals[y] > smallBeside(g.tree, x);
  }
  // The most terminals a vessel beside trunk x may have for the repair to regrow it rather than
  // let it stop the trunk.
  static std::int32_t smallBeside(const VascularTree& T, std::int32_t x) { return std::max(kMaxClearedTerminals, T.terminals[x] / kSmallBeside); }
  // Ancestor x refused a connection: counted towards its deferral, and listed to be checked
  // first next time.
  static void countRefusal(TreeGrowth& g, std::int32_t x) {
    if (g.blocks[x] < 255) ++g.blocks[x];
    if (std::find(g.blockers.begin(), g.blockers.end(), x) == g.blockers.end()) g.blockers[g.next_blocker++ % g.blockers.size()] = x;
  }
  // True if ancestor x of tree k's committed connection, at root radius rr, overlaps a vessel of
  // its own tree more than two segments away that blocks it (collides' check of one ancestor of
  // a single tree).
  template <class Radius, class Blocks>
  static bool overlapsOwnTree(TreeGrowth& g, std::int32_t x, double rr, Radius&& radius_of, Blocks&& blocks) {
    const auto& T = g.tree;
    const Vec3& a0 = T.position[T.parent[x]];
    const Vec3& a1 = T.position[x];
    const double rx = g.rel[x] * rr;
    const auto candidates = [&](auto&& f) {
      forEachNearVessel(g, a0, a1, rx, rr, radius_of, [&](std::int32_t y) {
        if (blocks(y)) f(y);
      });
    };
    return overlapsOtherVessel(T, x, a0, a1, rx, candidates, radius_of);
  }

  // Every kRefreshEvery terminals; at organ scale once the tree has grown by 1/kOrganRefreshShare
  // of itself (and at most every kRefreshEvery terminals): O(N) node visits in all, not O(N²).
  bool refreshDue(TreeGrowth& g) const {
    const std::int64_t n = g.terminalCount();
    if (!opt_.organ_scale) return n % kRefreshEvery == 0;
    if (n < g.next_refresh) return false;
    g.next_refresh = n + std::max(kRefreshEvery, n / kOrganRefreshShare);
    return true;
  }

  // ρ of the whole tree, and the list of thick segments.
  static void refreshRelativeRadii(TreeGrowth& g) {
    refreshRelative(g.tree, g.rel);
    g.thick.clear();
    for (std::int32_t s = 1; s < g.tree.nodeCount(); ++s)
      if (g.rel[s] >= kThick) g.thick.push_back(s);
  }

  // The whole-tree cost of tree k now, in the units of Connection::cost.
  double treeCostNow(const TreeGrowth& g) const {
    const auto root = g.tree.rootSegment();
    const double r = rootRadius(g.params, g.tree.terminals[root] * g.params.terminalFlow(), g.tree.reduced_resistance[root]);
    return g.kernel.radiusCost(r) * g.tree.cost_ratio[root];
  }

  // Connects p, drawn for system `sys`, through the cheapest valid bifurcation among the ν
  // nearest segments of each of its trees that still takes terminals, in space doubling ν while
  // none can be made. False when p lies in a vessel or no segment can take it.
  bool connect(const Vec3& p, const System& sys) {
    const std::int64_t n_sys_new = systemTerminals(sys) + 1;
    const double shrink_new = shrink(sys, n_sys_new);
    std::vector<int> open;
    for (int k : sys.trees)
      if (accepts(k) && trees_[k].tree.segmentCount() > 0) open.push_back(k);
    // Most points drawn into a dense planar tree lie inside a vessel, which Algorithm 2 refuses:
    // the segments listed in p's cell, then the few nearest (the first of the ν nearest), settle
    // that before the ν are sought.
    for (int k : open) {
      auto& g = trees_[k];
      const double rr = currentRootRadius(g);
      if (g.index.anyInCell(g.tree, p, [&](std::int32_t id, double d) { return d <= g.rel[id] * rr; })) return false;
      g.index.nearest(g.tree, p, kInsideProbe, g.near);
      for (const auto& [d, id] : g.near)
        if (d <= g.rel[id] * rr) return false;
    }
    // A tree's connection adds its new cost minus its cost now; alone, it ranks by its cost.
    const bool competing = open.size() > 1;
    std::vector<BifurcationOptimizer> opts;
    std::vector<double> base, rr_now;
    std::vector<std::int64_t> n_new;
    for (int k : open) {
      auto& g = trees_[k];
      opts.emplace_back(g.tree, g.params, nullptr, 0.0);  // `fits` tests the result's capsules against the domain
      base.push_back(competing ? treeCostNow(g) : 0.0);
      rr_now.push_back(currentRootRadius(g));
      n_new.push_back(g.terminalCount() + 1);
      g.done = 0;
    }
    if (trials_.size() < open.size()) trials_.resize(open.size());
    int nu = opt_.closest_neighbours;
    for (bool first = true;; first = false) {
      for (std::size_t i = 0; i < open.size(); ++i) {
        auto& g = trees_[open[i]];
        g.index.nearest(g.tree, p, nu, g.near);
        if (first)
          for (const auto& [d, id] : g.near)
            if (d <= g.rel[id] * rr_now[i]) return false;  // inside a vessel (Algorithm 2)
        // Vessels so near p that a new terminal's vessel there would touch them.
        g.crowding.clear();
        for (const auto& [d, id] : g.near)
          if (d - g.rel[id] * rr_now[i] < kCrowdedTerminal * g.terminal_radius) g.crowding.push_back(id);
      }
      ranked_.clear();
      for (std::size_t i = 0; i < open.size(); ++i) {
        auto& g = trees_[open[i]];
        auto& trials = trials_[i];
        trials.resize(g.near.size());
        // One task per segment: the other thread is often asleep when a candidate arrives and
        // wakes too late to take half of the list.
        const bool planar = dom_.dimension() == 2;
        // Whether trial j's exact refinement runs (all that qualify, or at organ scale only those
        // refine_set marks).
        const auto refineTrial = [&](std::size_t j) {
          const auto& k = trials[j].c[0];
          if (opt_.bifurcation == BifurcationPoint::Exact && (k.valid || (j < kRefineNearest && !trials[j].at_node)))
            trials[j].c[1] = refine(g, k, g.near[j].second, p, n_new[i], shrink_new, opts[i]);
          if (planar)
            for (int w : {0, 1}) trials[j].crosses[w] = trials[j].c[w].valid && terminalCrossesInPlane(g.tree, trials[j].c[w], g.near);
        };
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(g.done, g.near.size(), 1),
            [&](const auto& r) {
              for (auto j = r.begin(); j != r.end(); ++j) {
                // Half the ν nearest segments are hidden so on the disc (separatedInPlane).
                const bool hidden = planar && separatedInPlane(g.tree, g.near[j].second, p, g.near, kOccluders);
                if (hidden || crowdedOut(g, g.near[j].second)) {
                  trials[j] = Trial();
                  trials[j].hidden = hidden;
                  trials[j].crowded = !hidden;
                  continue;
                }
                trials[j] = evaluate(g, g.near[j].second, p, n_new[i], shrink_new, opts[i]);
                // The exact point where Kamiya found a valid one, and on the kRefineNearest nearest
                // segments where he found none (merged or l <= 2r: there the exact optimum often
                // lies inside): nearly the volume of refining every segment at a fraction of its cost.
                // In the plane, not where his point merged into the proximal node and the exact
                // optimum lies there too (the weighted Fermat condition, one walk): the steps would
                // only slide towards the node, where the parent part is short, and skipping them saves
                // time at no cost in volume. In space such steps, stopped short of the node, are often
                // valid, and without them the trees come out heavier (docs/benchmarks.md, as above).
                trials[j].at_node = planar && opt_.bifurcation == BifurcationPoint::Exact && j < kRefineNearest && trials[j].merged_at_parent &&
                                    opts[i].optimumAtProximalNode(g.near[j].second, p);
                if (!opt_.organ_scale) refineTrial(j);
              }
            },
            tbb::simple_partitioner());
        if (opt_.organ_scale) {
          // At organ scale only the kOrganRefined lightest of Kamiya's valid points, and the
          // kOrganRefined nearest segments where he found none, are refined: each refinement walks
          // to the root several times, and the walk grows with the tree (docs/benchmarks.md).
          refine_set_.clear();
          for (std::size_t j = g.done; j < g.near.size(); ++j)
            if (trials[j].c[0].valid) refine_set_.push_back(j);
          std::sort(refine_set_.begin(), refine_set_.end(),
                    [&](std::size_t a, std::size_t b) { return std::tie(trials[a].c[0].cost, a) < std::tie(trials[b].c[0].cost, b); });
          if (refine_set_.size() > kOrganRefined) refine_set_.resize(kOrganRefined);
          std::size_t nearest_invalid = 0;
          for (std::size_t j = g.done; j < g.near.size() && nearest_invalid < kOrganRefined; ++j)
            if (!trials[j].c[0].valid && !trials[j].hidden && !trials[j].crowded && j < kRefineNearest && !trials[j].at_node)
              refine_set_.push_back(j), ++nearest_invalid;
          tbb::parallel_for(
              tbb::blocked_range<std::size_t>(0, refine_set_.size(), 1),
              [&](const auto& r) {
                for (auto q = r.begin(); q != r.end(); ++q) refineTrial(refine_set_[q]);
              },
              tbb::simple_partitioner());
        }
        for (std::size_t j = g.done; j < g.near.size(); ++j) {
          if (trials[j].kamiya_failed) ++report_.kamiya_failures;
          if (trials[j].hidden) ++report_.hidden_segments;
          report_.crowded_segments += trials[j].crowded;
          report_.node_optima += trials[j].at_node;
          if (trials[j].c[0].valid) ranked_.push_back({int(i), j, 0, trials[j].c[0].cost - base[i]});
          if (trials[j].c[1].valid) ranked_.push_back({int(i), j, 1, trials[j].c[1].cost - base[i]});
        }
      }
      std::sort(ranked_.begin(), ranked_.end(), [&](const Candidate& a, const Candidate& b) {
        return std::tie(a.added, a.tree, trials_[a.tree][a.trial].c[a.which].segment, a.which) <
               std::tie(b.added, b.tree, trials_[b.tree][b.trial].c[b.which].segment, b.which);
      });

      for (const auto& cand : ranked_) {
        const int k = open[cand.tree];
        auto& g = trees_[k];
        Trial& trial = trials_[cand.tree][cand.trial];
        Connection& c = trial.c[cand.which];
        if (trial.crosses[cand.which]) {
          ++report_.rejected_intersection;
          continue;
        }
        // The path fits() summed, now recorded: the tree is as it was then (a refused
        // connection is rolled back), so the values are the same.
        opts[cand.tree].record(c);
        const auto undo = commitConnection(g.tree, c, opts[cand.tree], g.kernel, g.rel);
        const double rr = rootRadiusFinal(g, n_new[cand.tree], c.path.back().reduced_resistance, shrink_new);
        if (!collides(k, c, rr)) {
          for (auto x : check_) g.checked[x] = g.rel[x] * rr;
          const auto n = g.tree.nodeCount();
          g.index.insert(g.tree, n - 2);
          g.index.insert(g.tree, n - 1);
          g.index.insert(g.tree, c.segment);
          g.index.refresh(g.tree);
          if (g.rel[n - 2] >= kThick) g.thick.push_back(n - 2);
          if (refreshDue(g)) {
            refreshRelativeRadii(g);
            // Banded γ reads each bifurcation's parent radius: the radii in final units as they stand now.
            if (g.kernel.law().banded()) {
              const double r_root = currentRootRadius(g);
              for (std::int32_t x = 1; x < g.tree.nodeCount(); ++x) g.tree.radius[x] = g.rel[x] * r_root;
            }
          }
          g.terminal_radius = g.rel[n - 1] * rr;
          return true;
        }
        rollbackConnection(g.tree, undo, g.rel);
        ++report_.rejected_intersection;
      }
      bool more = false;
      for (int k : open) {
        auto& g = trees_[k];
        g.done = g.near.size();
        more |= static_cast<std::int32_t>(g.done) < g.tree.segmentCount();
      }
      // ν doubles only where a user asks for it (max_closest_neighbours), and never in the plane.
      // The segments beyond the ν nearest are reached by long, heavy connections, around the
      // vessels near the point (in the plane across them: half of the ν nearest are hidden
      // already). Without doubling, every tree measured came out lighter (docs/benchmarks.md, as
      // above).
      if (!more || nu >= opt_.max_neighbours || dom_.dimension() == 2) return false;
      nu = std::min(2 * nu, opt_.max_neighbours);
      ++report_.neighbour_doublings;
    }
  }

  // True if a vessel near the point (g.crowding) is more than two segments from the terminal
  // segment of a connection that splits s: the collision check would refuse every connection on
  // s, as the terminal segment's capsule ends at the point and reaches that vessel. Such trials
  // are not costed: most of them would go to points that connect nowhere.
  static bool crowdedOut(const TreeGrowth& g, std::int32_t s) {
    return std::any_of(g.crowding.begin(), g.crowding.end(), [&](std::int32_t y) { return !besideSplit(g.tree, s, y); });
  }

  // The system furthest behind its target (systems grow in step), or -1 when all are complete.
  int nextSystem() const {
    int best = -1;
    double best_fill = 1;
    for (std::size_t s = 0; s < systems_.size(); ++s) {
      const double fill = double(systemTerminals(systems_[s])) / double(systems_[s].target);
      if (fill < best_fill) best = int(s), best_fill = fill;
    }
    return best;
  }

  void growUntilTargets(const ProgressFn& progress) {
    std::int64_t total = 0, next_report = 0;
    for (const auto& s : systems_) total += s.target;
    const auto grown = [&] {
      std::int64_t n = 0;
      for (const auto& g : trees_) n += g.terminalCount();
      return n;
    };
    for (int si; (si = nextSystem()) >= 0;) {
      const System& sys = systems_[si];
      if (progress && grown() >= next_report) {
        progress(grown(), total);
        next_report = grown() + std::max<std::int64_t>(1, total / 200);
      }
      if (const auto empty = std::find_if(sys.trees.begin(), sys.trees.end(), [&](int k) { return trees_[k].tree.segmentCount() == 0; });
          empty != sys.trees.end()) {
        plantFirst(*empty);
        continue;
      }
      const std::int64_t n = systemTerminals(sys);
      // δ_max for the system's current number of terminals, relaxed by runs of failures.
      double delta = dom_.terminalSpacing(n);
      // At organ scale the threshold the last connection was made at carries over: starting from
      // δ_max again, every terminal of a large tree spends a run of rejected draws relaxing it.
      if (opt_.organ_scale && relaxed_[std::size_t(si)] > 0) delta = std::min(delta, relaxed_[std::size_t(si)]);
      std::int64_t unconnectable = 0;  // of this run of failures
      for (std::int64_t failures = 1;; ++failures) {
        if (failures > opt_.max_draws || unconnectable >= opt_.max_unconnectable)
          throw GrowthError("could place only " + std::to_string(n) + " of " + std::to_string(sys.target) + " terminals" +
                            (systems_.size() > 1 ? " of system " + std::to_string(si + 1) : std::string()) + ": " +
                            (failures > opt_.max_draws ? std::to_string(opt_.max_draws) + " points in a row"
                                                       : std::to_string(unconnectable) + " points in a row far enough from every vessel") +
                            " found no valid connection "
                            "(too close " +
                            std::to_string(report_.rejected_too_close) + ", unconnectable " + std::to_string(report_.rejected_unreachable) +
                            "); lower the number of terminals or enlarge the domain");
        // An ancestor on every path (a trunk) that thickened against another tree's vessel would
        // refuse every connection of its tree for ever: after a long run of failures, ancestors
        // are no longer checked against other trees; the exact final check and repair see them.
        if (failures == 1) ancestor_blocks_ = 0;
        lenient_ = ancestor_blocks_ > kLenientAfter;
        const Vec3 p = drawPoint();
        const double spacing = delta * dom_.spacingScale(p);
        if (std::any_of(sys.trees.begin(), sys.trees.end(), [&](int k) { return tooClose(k, p, spacing); })) {
          ++report_.rejected_too_close;
        } else {
          ++report_.candidates;
          if (connect(p, sys)) {
            report_.lenient_connections += skipped_;
            relaxed_[std::size_t(si)] = delta;
            break;
          }
          ++report_.rejected_unreachable;
          ++unconnectable;
        }
        if (failures % opt_.draws_before_relaxing == 0) {
          delta *= opt_.relaxation;
          ++report_.threshold_relaxations;
        }
      }
    }
    if (progress) progress(grown(), total);
  }

  // True if a point drawn at p lies within `spacing` of tree k (its terminal points, or every
  // segment with TerminalSpacing::Segments).
  bool tooClose(int k, const Vec3& p, double spacing) {
    auto& g = trees_[k];
    if (opt_.spacing_from == TerminalSpacing::Segments) return g.index.anyWithin(g.tree, p, spacing);
    const auto& T = g.tree;
    if (!g.terminal_grid || T.nodeCount() < g.grid_nodes || g.terminalCount() >= 2 * g.grid_built) {
      const double delta = dom_.terminalSpacing(std::max<std::int64_t>(1, g.terminalCount()));
      g.terminal_grid = std::make_unique<PointHash>(dom_.lo(), dom_.hi(), std::max(spacing, delta), dom_.dimension() == 2);
      g.grid_nodes = 0;
      g.grid_built = g.terminalCount();
    }
    for (; g.grid_nodes < T.nodeCount(); ++g.grid_nodes)
      if (g.grid_nodes > 0 && T.isTerminal(g.grid_nodes)) g.terminal_grid->insert(T.position[g.grid_nodes], g.grid_nodes);
    const double s2 = spacing * spacing;
    return g.terminal_grid->anyNear(p, spacing, [&](std::int32_t id) {
      const Vec3 d = T.position[id] - p;
      return dot(d, d) < s2;
    });
  }

  // True if the solved tree's segment x, with ends a–e, stays in the domain, longer than twice
  // its radius and clear of every vessel more than one segment away and of the other trees
  // (radii with 2 % margin).
  // With `regrow`, a vessel of the same tree with at most `small` terminals does not count: it
  // is appended there, for the repair to remove and regrow.
  bool segmentFits(int k, std::int32_t x, const Vec3& a, const Vec3& e, std::vector<std::int32_t>* regrow = nullptr, std::int32_t small = 0) {
    auto& g = trees_[k];
    const auto& T = g.tree;
    const double rx = 1.02 * T.radius[x];
    if (!(distance(a, e) > 2 * rx) || !dom_.capsuleInside(a, e, rx, startsAtRoot(g, x))) return false;
    const double reach = rx + 1.02 * T.radius[T.rootSegment()];
    const auto candidates = [&](auto&& f) {
      g.index.forEachNearSegment(a, e, reach, [&](std::int32_t y) {
        if (!regrow || y >= T.nodeCount() || T.terminals[y] > small) return f(y);
        if (y != x && overlapsApart(T, x, a, e, rx, y, 1.02 * T.radius[y])) regrow->push_back(y);
      });
    };
    if (overlapsOtherVessel(T, x, a, e, rx, candidates, [&](std::int32_t y) { return 1.02 * T.radius[y]; })) return false;
    return trees_.size() == 1 || !hitsOtherTree(k, a, e, rx, true);
  }

  // Moves node v of tree k to q if every segment meeting there still fits; restores it otherwise.
  // With `regrow`, small vessels in the way are listed there instead (segmentFits).
  bool tryMove(int k, std::int32_t v, const Vec3& q, std::vector<std::int32_t>* regrow = nullptr, std::int32_t small = 0) {
    return tryMove(k, {v, -1}, {q, q}, regrow, small);
  }
  // The same for one node v[0] or two (v[1] >= 0), moved together.
  bool tryMove(int k, const std::array<std::int32_t, 2>& v, const std::array<Vec3, 2>& q, std::vector<std::int32_t>* regrow = nullptr,
               std::int32_t small = 0) {
    auto& g = trees_[k];
    auto& T = g.tree;
    const int n = v[1] >= 0 ? 2 : 1;
    Vec3 old[2];
    std::vector<std::int32_t> segs;
    for (int i = 0; i < n; ++i) {
      old[i] = T.position[v[i]];
      T.position[v[i]] = q[i];
      for (auto x : {v[i], T.child0[v[i]], T.child1[v[i]]})
        if (x > 0 && std::find(segs.begin(), segs.end(), x) == segs.end()) segs.push_back(x);
    }
    const std::size_t listed = regrow ? regrow->size() : 0;
    bool ok = true;
    for (auto x : segs)
      if (ok) ok = segmentFits(k, x, T.position[T.parent[x]], T.position[x], regrow, small);
    if (!ok) {
      for (int i = n - 1; i >= 0; --i) T.position[v[i]] = old[i];
      if (regrow) regrow->resize(listed);
      return false;
    }
    for (auto x : segs) g.index.insert(T, x);
    return true;
  }

  // A trunk that thickened past half its length since it was made: slide its distal
  // bifurcation outwards (along the trunk, or towards its children), or its proximal one back,
  // to 2.1–3 r, or move either end away from every segment end it is too close to, whichever
  // first fits. Failing that, the same moves to 2.1 r where only small
  // vessels (at most kMaxClearedTerminals terminals or 1/kSmallBeside of the trunk's, fewer
  // than its own, so none of its ancestors) are in the way: they go to `regrow`. A trunk left
  // short is typically blocked by a single terminal segment.
  bool lengthen(int k, std::int32_t s, std::vector<std::int32_t>& regrow) {
    if (lengthenFree(k, s)) return true;
    const auto& T = trees_[k].tree;
    const auto P = T.parent[s];
    const Vec3 a = T.position[P], e = T.position[s];
    const Vec3 u = (e - a) / distance(a, e);
    const double L = 2.1 * T.radius[s];
    const std::int32_t small = std::min(smallBeside(T, s), T.terminals[s] - 1);
    if (!T.isTerminal(s) && tryMove(k, s, a + u * L, &regrow, small)) return true;
    if (P > 0 && tryMove(k, P, e - u * L, &regrow, small)) return true;
    return slideWithNeighbour(k, s, &regrow, small) || spreadEnd(k, s, &regrow, small);
  }

  // Either end of s moved away from every node it is too close to (spreadEitherEnd).
  bool spreadEnd(int k, std::int32_t s, std::vector<std::int32_t>* regrow = nullptr, std::int32_t small = 0) {
    return spreadEitherEnd(trees_[k].tree, s, 2, [&](std::int32_t v, const Vec3& q) { return tryMove(k, v, q, regrow, small); });
  }

  // In a chain of trunks each near 2r, neither neighbour has the room alone: both ends of s
  // slide half way, to 2.1 r or 2.05 r (a trunk whose parent and larger child each have half
  // the length it lacks). Or the distal end slides on with one child,
  // which keeps its length: a root segment's proximal end cannot move (a root segment just over
  // 2r whose larger child would come a hair short of its own 2r).
  bool slideWithNeighbour(int k, std::int32_t s, std::vector<std::int32_t>* regrow = nullptr, std::int32_t small = 0) {
    const auto& T = trees_[k].tree;
    const auto P = T.parent[s];
    if (P < 0 || T.isTerminal(s)) return false;
    const Vec3 a = T.position[P], e = T.position[s];
    const Vec3 u = (e - a) / distance(a, e);
    for (double f : {2.1, 2.05}) {
      const double grow = f * T.radius[s] - distance(a, e);
      if (P > 0 && tryMove(k, {P, s}, {a - u * (0.5 * grow), e + u * (0.5 * grow)}, regrow, small)) return true;
      for (const auto c : {T.child0[s], T.child1[s]})
        if (tryMove(k, {s, c}, {e + u * grow, T.position[c] + u * grow}, regrow, small)) return true;
    }
    return false;
  }

  // The slides of `lengthen` that every vessel in the way blocks.
  bool lengthenFree(int k, std::int32_t s) {
    const auto& T = trees_[k].tree;
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
      if (!T.isTerminal(s) && (tryMove(k, s, a + u * L) || tryMove(k, s, e + w * grow))) return true;
      if (P > 0 && tryMove(k, P, e - u * L)) return true;
    }
    if (T.isTerminal(s)) return false;
    if (slideWithNeighbour(k, s)) return true;
    // Blocked straight ahead (a root segment beside another tree's trunk): the distal
    // bifurcation on cones of 20° and 40° around the segment's direction (in the plane for 2D).
    Vec3 p1 = std::abs(u.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    if (dom_.dimension() == 2) p1 = Vec3(0, 0, 1);
    p1 = cross(u, p1);
    p1 = p1 / norm(p1);
    const Vec3 p2 = cross(u, p1);
    const int turns = dom_.dimension() == 2 ? 2 : 8;
    for (double f : {2.2, 2.6})
      for (double theta : {20.0, 40.0})
        for (int i = 0; i < turns; ++i) {
          const double t = theta * std::numbers::pi / 180, phi = 2 * std::numbers::pi * i / turns;
          const Vec3 d = u * std::cos(t) + (p1 * std::cos(phi) + p2 * std::sin(phi)) * std::sin(t);
          if (tryMove(k, s, a + d * (f * T.radius[s]))) return true;
        }
    return spreadEnd(k, s);
  }

  // A segment that the solved radii push out of the domain (its subtree too large to regrow):
  // move its distal node, else its proximal one, up the depth gradient by 0.5–3 r, whichever
  // first fits. Seen only where the final solve thickened a trunk next to a thin mask wall.
  bool pushInside(int k, std::int32_t s) {
    const auto& T = trees_[k].tree;
    const double h = dom_.frame().voxel_mm;
    for (const std::int32_t v : {s, T.parent[s]}) {
      if (v <= 0) continue;
      const Vec3 p = T.position[v];
      Vec3 g(dom_.depth(p + Vec3(h, 0, 0)) - dom_.depth(p - Vec3(h, 0, 0)), dom_.depth(p + Vec3(0, h, 0)) - dom_.depth(p - Vec3(0, h, 0)),
             dom_.dimension() == 2 ? 0.0 : dom_.depth(p + Vec3(0, 0, h)) - dom_.depth(p - Vec3(0, 0, h)));
      if (!(norm(g) > 0)) continue;
      g = g / norm(g);
      for (double f : {0.5, 1.0, 2.0, 3.0})
        if (tryMove(k, v, p + g * (f * T.radius[s]))) return true;
    }
    return false;
  }

  // Moves an end of segment x (tree k) away from segment y (tree j) that it overlaps, by the
  // overlap and a margin, if every segment meeting there still fits.
  bool separate(int k, std::int32_t x, int j, std::int32_t y) {
    const auto& T = trees_[k].tree;
    const auto& O = trees_[j].tree;
    const Vec3 &b0 = O.position[O.parent[y]], &b1 = O.position[y];
    for (const std::int32_t v : {x, T.parent[x]}) {
      if (v <= 0) continue;
      const Vec3 p = T.position[v];
      const Vec3 ab = b1 - b0;
      const double t = std::clamp(dot(p - b0, ab) / std::max(dot(ab, ab), 1e-300), 0.0, 1.0);
      const Vec3 away = p - (b0 + ab * t);
      if (!(norm(away) > 0)) continue;
      const double gap = 1.05 * (T.radius[x] + O.radius[y]) - segmentSegmentDistance(T.position[T.parent[x]], T.position[x], b0, b1);
      for (double f : {1.0, 1.5, 2.5, 4.0})
        if (tryMove(k, v, p + away / norm(away) * (f * std::max(gap, 0.0) + 0.1 * T.radius[x]))) return true;
    }
    return false;
  }

  bool tooLargeToRegrow(int k, std::int32_t s) const {
    return trees_[k].tree.terminals[s] > kMaxRepairShare * double(systems_[trees_[k].system].target);
  }

  // Segments of the solved forest that break a constraint, per tree: intersecting pairs (within
  // and across trees), length <= 2r, or leaving the domain. Short trunks are lengthened in
  // place; for the rest, the segment whose subtree removal costs fewest terminals is listed.
  std::vector<std::vector<std::int32_t>> violations() {
    std::vector<std::vector<std::int32_t>> out(trees_.size());
    short_fixes_.clear();
    // Every pair, within and across trees, on the forest of all trees (ids shifted per tree).
    VascularTree forest;
    std::vector<std::int32_t> offset;
    for (std::size_t k = 0; k < trees_.size(); ++k) {
      offset.push_back(forest.nodeCount());
      forest.appendTree(trees_[k].tree, int(k));
    }
    const auto local = [&](std::int32_t x) { return std::pair<int, std::int32_t>(forest.tree[x], x - offset[forest.tree[x]]); };
    const auto pairs = intersectingPairs(forest, dom_.lo(), dom_.hi());
    report_.intersecting_pairs = static_cast<std::int64_t>(pairs.size());
    for (const auto& [fx, fy] : pairs) {
      const auto [kx, x] = local(fx);
      const auto [ky, y] = local(fy);
      const auto nx = trees_[kx].tree.terminals[x], ny = trees_[ky].tree.terminals[y];
      const bool x_goes = std::tie(nx, fy) < std::tie(ny, fx);
      // Two trunks, both too large to regrow: push the thinner one aside, else the thicker.
      const auto [kt, t, kw, w] = x_goes ? std::tuple(kx, x, ky, y) : std::tuple(ky, y, kx, x);
      // At organ scale also where the lighter side is a subtree of more than a few terminals:
      // trunks that grew into their neighbours would otherwise send hundreds of thousands of
      // terminals to be regrown at a million (docs/benchmarks.md).
      const bool both_large = tooLargeToRegrow(kx, x) && tooLargeToRegrow(ky, y);
      const bool worth_moving = opt_.organ_scale && std::min(nx, ny) > kMaxClearedTerminals;
      if ((both_large || worth_moving) && (separate(kt, t, kw, w) || separate(kw, w, kt, t))) {
        ++report_.moved_nodes;
        continue;
      }
      if (x_goes)
        out[kx].push_back(x);
      else
        out[ky].push_back(y);
    }
    report_.short_segments = report_.outside_segments = 0;
    for (std::size_t k = 0; k < trees_.size(); ++k) trees_[k].index.refresh(trees_[k].tree, true);
    for (std::size_t kk = 0; kk < trees_.size(); ++kk) {
      const int k = int(kk);
      const auto& T = trees_[k].tree;
      for (std::int32_t s = 1; s < T.nodeCount(); ++s) {
        if (!(T.length[s] > 2 * T.radius[s])) {
          ++report_.short_segments;
          if (std::vector<std::int32_t> regrow; lengthen(k, s, regrow)) {
            ++report_.moved_nodes;
            out[k].insert(out[k].end(), regrow.begin(), regrow.end());
          } else if (T.isTerminal(s)) {
            out[k].push_back(s);
          } else {  // the trunk merges with its larger child when the smaller child's subtree goes
            const auto gone = T.terminals[T.child0[s]] <= T.terminals[T.child1[s]] ? T.child0[s] : T.child1[s];
            out[k].push_back(gone);
            short_fixes_.emplace_back(k, gone);
          }
        }
        if (!dom_.capsuleInside(T.position[T.parent[s]], T.position[s], T.radius[s], startsAtRoot(trees_[k], s))) {
          ++report_.outside_segments;
          if (tooLargeToRegrow(k, s) && pushInside(k, s))
            ++report_.moved_nodes;
          else
            out[k].push_back(s);
        }
      }
      auto& o = out[k];
      std::sort(o.begin(), o.end());
      o.erase(std::unique(o.begin(), o.end()), o.end());
    }
    return out;
  }

  void solveAll() {
    for (auto& g : trees_) solveTree(g.tree, g.params);
  }

  // Solves the exact final trees; removes and regrows the branches that break a constraint.
  void repair(const ProgressFn& progress) {
    repairing_ = true;
    for (int round = 0;; ++round) {
      solveAll();
      const auto moved_before = report_.moved_nodes;
      auto bad = violations();
      bool none = true;
      for (std::size_t k = 0; k < trees_.size(); ++k) {
        // A trunk that neither end can lengthen (both crowded) may lose a larger side branch.
        std::erase_if(bad[k], [&](std::int32_t s) {
          const bool short_fix = std::find(short_fixes_.begin(), short_fixes_.end(), std::pair<int, std::int32_t>(int(k), s)) != short_fixes_.end();
          return short_fix ? trees_[k].tree.terminals[s] > kMaxShortRepairShare * double(systems_[trees_[k].system].target)
                           : tooLargeToRegrow(int(k), s);
        });
        none &= bad[k].empty();
      }
      const bool moved = report_.moved_nodes > moved_before;
      if ((none && !moved) || round == opt_.max_repair_rounds) return;
      ++report_.repair_rounds;
      for (std::size_t k = 0; k < trees_.size(); ++k) {
        auto& g = trees_[k];
        if (!bad[k].empty()) {
          const auto before = g.terminalCount();
          g.tree.removeSubtrees(bad[k]);
          report_.repaired_terminals += before - g.terminalCount();
        }
      }
      solveAll();
      for (auto& g : trees_) {
        refreshRelativeRadii(g);
        g.checked = g.tree.radius;               // the exact check just passed every kept segment
        g.blocks.assign(g.tree.nodeCount(), 0);  // ids change when subtrees go
        g.index.refresh(g.tree, true);
        g.terminal_grid.reset();
      }
      growUntilTargets(progress);
    }
  }

  std::vector<std::pair<int, std::int32_t>> short_fixes_;  // (tree, side branch) removals for short trunks
  const GrowthDomain& dom_;
  const CcoOptions& opt_;
  GrowthReport& report_;
  Rng rng_;
  std::vector<TreeGrowth> trees_;
  std::vector<System> systems_;
  std::vector<std::size_t> refine_set_;     // trials refined at organ scale
  std::vector<double> relaxed_;             // per system: the last connection's distance threshold
  std::vector<std::vector<Trial>> trials_;  // per open tree of the connection being made
  std::vector<Candidate> ranked_;
  std::vector<std::int32_t> check_;
  bool repairing_ = false;
  bool lenient_ = false;
  bool skipped_ = false;  // the last collision check skipped an ancestor's check against other trees
  std::int64_t ancestor_blocks_ = 0;
};

}  // namespace

std::vector<VascularTree> growCcoForest(const GrowthDomain& domain, const CcoOptions& options, const std::vector<CcoInlet>& inlets,
                                        GrowthReport& report, const ProgressFn& progress) {
  CcoGrower g(domain, options, inlets, report);
  return g.run(progress);
}

VascularTree growCco(const GrowthDomain& domain, const CcoOptions& options, GrowthReport& report, const ProgressFn& progress) {
  CcoInlet in;
  in.root_mm = options.root_mm;
  in.root_pressure = options.physics.perfusion_pressure;
  in.terminal_pressure = options.physics.terminal_pressure;
  return std::move(growCcoForest(domain, options, {in}, report, progress).front());
}

PhysicsParameters inletPhysics(PhysicsParameters p, double root_pressure, double terminal_pressure) {
  p.perfusion_pressure = root_pressure;
  p.terminal_pressure = terminal_pressure;
  return p;
}

std::vector<std::int64_t> terminalQuotas(const std::vector<double>& shares, std::int64_t n) {
  std::vector<std::int64_t> q(shares.size(), 0);
  double fixed = 0;
  bool all_fixed = true;
  for (std::size_t i = 0; i < shares.size(); ++i) {
    q[i] = std::int64_t(std::floor(shares[i] * double(n)));
    fixed += shares[i];
    all_fixed &= shares[i] > 0;
  }
  if (!all_fixed || std::abs(fixed - 1) > 1e-9) return q;
  // Shares that sum to 1: the terminals left by rounding down go to the largest remainders.
  std::vector<std::size_t> order(shares.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto remainder = [&](std::size_t i) { return shares[i] * double(n) - double(q[i]); };
  std::stable_sort(order.begin(), order.end(), [&](auto a, auto b) { return remainder(a) > remainder(b); });
  std::int64_t left = n;
  for (auto v : q) left -= v;
  for (std::size_t i = 0; left > 0; i = (i + 1) % order.size(), --left) ++q[order[i]];
  return q;
}

}  // namespace angiosynth
