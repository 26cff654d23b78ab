#include "grow/vascusynth/grower.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <tuple>

#include "core/distributions.hpp"
#include "core/rng.hpp"
#include "domain/clear_paths.hpp"
#include "domain/demand_sampler.hpp"
#include "domain/supply.hpp"
#include "grow/common/bifurcation_optimizer.hpp"
#include "grow/common/connection_commit.hpp"
#include "grow/common/intersections.hpp"
#include "grow/common/spread_bifurcation.hpp"
#include "core/segment_index.hpp"

namespace angiosynth {
namespace {

// How many ancestors above a new bifurcation are re-checked for collisions when they thicken;
// higher ones change by a negligible factor per terminal and are covered by the final check.
constexpr int kAncestorsChecked = 6;
// Radii are checked at their predicted final size. The root grows as r ∝ n^a (a measured on the
// growing tree, about 0.29 for VascuSynth's example, clamped to [0.2, 0.4] against early noise);
// the prediction holds for the trunk but overstates thin peripheral branches, so it is capped
// (scaling each vessel by its flow share instead leaves many more collisions: docs/benchmarks.md).
constexpr double kMaxPredictedScale = 4.0;
// The final repair never removes more than this share of the terminals for one collision.
constexpr double kMaxRepairShare = 0.05;

// Segments by position for the final check, whose radii stay fixed between rebuilds. A query
// must reach as far as the thickest vessel it could touch; reaching the root's radius from every
// thin vessel would scan many cells, so the few vessels thicker than kThickShare × the root's
// radius also sit in a sparse index of their own, searched that far, and the full index is
// searched only as far as the thickest of the others.
class VesselIndex {
 public:
  VesselIndex(const VascularTree& tree, const Vec3& lo, const Vec3& hi) : all_(lo, hi), thick_(lo, hi) { rebuild(tree); }
  void rebuild(const VascularTree& tree) {
    r_max_ = tree.segmentCount() > 0 ? tree.radius[tree.rootSegment()] : 0.0;
    r_thin_ = kThickShare * r_max_;
    all_.refresh(tree, true);
    std::vector<std::int32_t> thick;
    for (std::int32_t s = 1; s < tree.nodeCount(); ++s)
      if (!tree.isRoot(s) && tree.radius[s] > r_thin_) thick.push_back(s);
    thick_.rebuild(tree, thick);
  }
  void insert(const VascularTree& tree, std::int32_t s) {
    all_.insert(tree, s);
    if (tree.radius[s] > r_thin_) thick_.insert(tree, s);
  }
  // Calls f(id) for every segment that may lie closer to a–e than r + margin × its radius (some
  // more than once).
  template <class F>
  void forEachNearVessel(const Vec3& a, const Vec3& e, double r, double margin, F&& f) {
    all_.forEachNearSegment(a, e, r + margin * r_thin_, f);
    thick_.forEachNearSegment(a, e, r + margin * r_max_, f);
  }

 private:
  static constexpr double kThickShare = 0.1;
  SegmentIndex all_, thick_;
  double r_max_ = 0, r_thin_ = 0;
};

class Grower {
 public:
  Grower(const DemandMap& map, const GrowthOptions& o, GrowthReport& report)
      : map_(map),
        paths_(map),
        opt_(o),
        report_(report),
        params_(o.physics),
        sampler_(map.demand),
        index_(Vec3(0, 0, 0), map.extentMm()),
        rng_(o.seed, o.sample, Stage::Growth) {
    params_.total_terminals = o.terminals;
    min_length_ = o.minSegmentLength(map.voxel_mm);
    tree_.reserve(2 * o.terminals + 1);
    tree_.addNode(o.root_mm, -1);
    root_history_.assign(o.terminals + 2, 0.0);
  }

  VascularTree run(const ProgressFn& progress) {
    growUntil(opt_.terminals, progress);
    solveTree(tree_, params_);
    const bool checked = opt_.avoid_intersections || opt_.min_length_ratio > 0;
    if (checked) repair(progress);  // leaves the tree solved
    relaxBifurcations();
    if (checked) repair(progress);  // the re-solved radii may leave a vessel just short of the ratio
    report_.short_segments = static_cast<std::int64_t>(shortSegments().size());
    report_.intersecting_pairs = static_cast<std::int64_t>(intersectingPairs(tree_, Vec3(0, 0, 0), map_.extentMm()).size());
    report_.root_radius_mm = tree_.radius[tree_.rootSegment()];
    return std::move(tree_);
  }

 private:
  Vec3 drawCandidate() {
    for (;;) {
      const auto v = sampler_.sample(rng_.uniform());
      const Vec3 jitter = uniformPoint(rng_, 0, 1);
      if (v < 0) continue;
      const std::int64_t nx = map_.dims[0], ny = map_.dims[1];
      const Vec3 corner(double(v % nx), double((v / nx) % ny), double(v / (nx * ny)));
      return map_.toMm(corner + jitter);
    }
  }

  void growUntil(std::int64_t target, const ProgressFn& progress) {
    std::int64_t consecutive = 0;
    std::vector<std::pair<double, std::int32_t>> near;
    std::vector<Connection> trials;
    std::int64_t next_report = 0;
    while (tree_.terminalCount() < target) {
      if (progress && tree_.terminalCount() >= next_report) {
        progress(tree_.terminalCount(), target);
        next_report = tree_.terminalCount() + std::max<std::int64_t>(1, target / 200);
      }
      if (consecutive >= opt_.max_consecutive_rejections || !(sampler_.total() > 0))
        throw GrowthError("could place only " + std::to_string(tree_.terminalCount()) + " of " + std::to_string(target) + " terminals: " +
                          std::to_string(consecutive) + " candidates in a row were rejected (demand left: " + std::to_string(sampler_.total()) +
                          "; too close " + std::to_string(report_.rejected_too_close) + ", unreachable " +
                          std::to_string(report_.rejected_unreachable) + ", colliding " + std::to_string(report_.rejected_intersection) +
                          "); lower the number of terminals or MIN_DISTANCE, or enlarge the demand map");
      ++consecutive;
      ++report_.candidates;
      const Vec3 cand = drawCandidate();
      if (tree_.segmentCount() == 0) {
        if (distance(tree_.position[0], cand) < min_length_ || !paths_.segmentClear(tree_.position[0], cand)) {
          ++report_.rejected_unreachable;
          continue;
        }
        const auto t = tree_.addNode(cand, 0);
        tree_.reduced_resistance[t] = tree_.length[t];
        tree_.cost_ratio[t] = PowerKernel(params_).lengthCost(tree_.length[t]);
        rel_.assign(2, 1.0);
        root_history_[1] = rootRadius(params_, params_.terminalFlow(), tree_.reduced_resistance[t]);
        index_.refresh(tree_, true);
        perfuseAt(cand);
        consecutive = 0;
        continue;
      }
      if (opt_.min_distance_mm > 0 && index_.anyWithin(tree_, cand, opt_.min_distance_mm)) {
        ++report_.rejected_too_close;
        continue;
      }
      index_.nearest(tree_, cand, opt_.closest_neighbours, near);
      if (opt_.min_length_ratio > 0) withFamilies(near);
      trials.assign(near.size(), Connection{});
      // Lengths are held to the ratio at radii grown towards the final tree: the root, whose
      // fixed proximal end the final check cannot slide back, by 1.1 × its predicted growth; thin
      // vessels by its square root (the trunk's growth overstates theirs, the present radii
      // understate it); the two parts of a split vessel by a growth between these, nearer the
      // root's the thicker the vessel is against the root (its radius share, squared, as the
      // exponent's weight), since a vessel carrying much of the root's flow thickens as the root
      // does. Measured over 20 seeds of examples/vascusynth_like.toml and at 10⁴ terminals, this
      // leaves the fewest vessels for the final check to lengthen or regrow at the lowest cost
      // (docs/methods/vascusynth.md).
      const double growth = rootGrowth();
      const BifurcationOptimizer opt(tree_, params_, &paths_, min_length_, opt_.min_length_ratio, std::sqrt(finalScale()), 1.1 * growth, &rel_);
      std::vector<std::size_t> order;
      if (near.size() > std::size_t(opt_.closest_neighbours)) {
        // Near segments and their families: each costed at its starting point, and only the
        // closest_neighbours cheapest optimised (the cheapest start is almost always the
        // cheapest optimum; optimising all of them tripled the growth time).
        tbb::parallel_for(std::size_t(0), near.size(), [&](std::size_t i) { trials[i] = opt.optimise(near[i].second, cand, 0); });
        for (std::size_t i = 0; i < trials.size(); ++i)
          if (trials[i].valid) order.push_back(i);
        const auto kept = std::min(order.size(), std::size_t(opt_.closest_neighbours));
        std::partial_sort(order.begin(), order.begin() + std::ptrdiff_t(kept), order.end(),
                          [&](auto a, auto b) { return std::tie(trials[a].cost, trials[a].segment) < std::tie(trials[b].cost, trials[b].segment); });
        order.resize(kept);
        tbb::parallel_for(std::size_t(0), order.size(), [&](std::size_t j) {
          auto& c = trials[order[j]];
          const Vec3 start = c.bifurcation;
          c = opt.optimise(c.segment, cand, 20, &start);
        });
        std::erase_if(order, [&](std::size_t i) { return !trials[i].valid; });
      } else {
        tbb::parallel_for(std::size_t(0), near.size(), [&](std::size_t i) { trials[i] = opt.optimise(near[i].second, cand); });
        for (std::size_t i = 0; i < trials.size(); ++i)
          if (trials[i].valid) order.push_back(i);
      }
      if (order.empty()) {
        ++report_.rejected_unreachable;
        continue;
      }
      std::sort(order.begin(), order.end(),
                [&](auto a, auto b) { return std::tie(trials[a].cost, trials[a].segment) < std::tie(trials[b].cost, trials[b].segment); });
      bool accepted = false;
      for (auto i : order) {
        Connection& c = trials[i];
        opt.polish(c);
        if (!opt.keepsLengthRatio(c)) continue;  // the polish moved it past a radius-scaled minimum
        opt.record(c);
        const ConnectionUndo undo = commit(c);
        if (!opt_.avoid_intersections || !collides(c)) {
          accepted = true;
          break;
        }
        rollback(undo);
      }
      if (!accepted) {
        ++report_.rejected_intersection;
        // A run of collisions means the predicted radii leave no room anywhere (seen on a few
        // early trees whose trunk lies along a face): relax the prediction towards the present
        // radii; the exact check of the final tree repairs what this lets through.
        if (++collisions_in_a_row_ % kCollisionsBeforeRelaxing == 0) relax_ *= 0.7;
        continue;
      }
      collisions_in_a_row_ = 0;
      relax_ = std::min(1.0, relax_ * 1.1);
      const auto n = tree_.nodeCount();
      index_.insert(tree_, n - 2);
      index_.insert(tree_, n - 1);
      index_.insert(tree_, tree_.child0[n - 2]);  // the split segment, now starting at b
      index_.refresh(tree_);
      perfuseAt(cand);
      consecutive = 0;
    }
    if (progress) progress(tree_.terminalCount(), target);
  }

  // Adds the parent and sibling of every near segment. Where the cheapest bifurcation on a
  // segment would merge into its proximal node, the length ratio pushes it away; the same
  // junction reached over the parent or the sibling is then often cheaper.
  void withFamilies(std::vector<std::pair<double, std::int32_t>>& near) const {
    const auto n = near.size();
    const auto add = [&](double d, std::int32_t id) {
      if (std::none_of(near.begin(), near.end(), [&](const auto& e) { return e.second == id; })) near.emplace_back(d, id);
    };
    for (std::size_t i = 0; i < n; ++i) {
      const auto [d, s] = near[i];
      if (tree_.parent[s] > 0) {
        add(d, tree_.parent[s]);
        add(d, tree_.sibling(s));
      }
    }
  }

  // Applies a recorded connection: new bifurcation b (splitting s) and terminal t.
  ConnectionUndo commit(const Connection& c) {
    const BifurcationOptimizer opt(tree_, params_, &paths_, min_length_);
    auto u = commitConnection(tree_, c, opt, PowerKernel(params_), rel_);
    root_history_[tree_.terminalCount()] = c.root_radius;
    return u;
  }

  void rollback(const ConnectionUndo& u) { rollbackConnection(tree_, u, rel_); }

  double relax_ = 1.0;  // < 1 after runs of collision rejections
  std::int64_t collisions_in_a_row_ = 0;
  static constexpr std::int64_t kCollisionsBeforeRelaxing = 500;

  // Radius scale from now to the final tree (for collisions: capped, and relaxed after runs of
  // collisions). The root's own growth, uncapped: `rootGrowth`.
  double finalScale() const { return std::max(1.0, relax_ * std::min(kMaxPredictedScale, rootGrowth())); }
  double rootGrowth() const {
    const std::int64_t n = tree_.terminalCount(), N = opt_.terminals;
    if (n >= N) return 1.0;
    double a = 1.0 / params_.murray_exponent;
    if (n >= 16 && root_history_[n / 2] > 0)
      a = std::clamp(std::log(root_history_[n] / root_history_[n / 2]) / std::log(double(n) / double(n / 2)), 0.2, 0.4);
    return std::pow(double(N) / double(n), a);
  }

  // True if the new segments (or the ancestors just above them) overlap another vessel, with
  // every radius scaled to its predicted final size.
  bool collides(const Connection& c) {
    const auto& t = tree_;
    const double scale = c.root_radius * finalScale();
    const double r_max = scale;
    const auto b = t.nodeCount() - 2;
    std::vector<std::int32_t> check{b, c.segment, b + 1};
    for (std::size_t lv = 1; lv < c.path.size() && lv <= kAncestorsChecked; ++lv) check.push_back(c.path[lv].segment);
    for (auto x : check) {
      const Vec3& a0 = t.position[t.parent[x]];
      const Vec3& a1 = t.position[x];
      const double rx = rel_[x] * scale;
      if (overlapsOtherVessel(
              t, x, a0, a1, rx, [&](auto&& f) { index_.forEachNearSegment(a0, a1, rx + r_max, f); }, [&](std::int32_t y) { return rel_[y] * scale; }))
        return true;
    }
    return false;
  }

  // True if removing segment s's subtree leaves a spliced segment that crosses no obstacle.
  bool spliceClear(std::int32_t s) const {
    const auto p = tree_.parent[s];
    if (p == 0) return true;
    return paths_.segmentClear(tree_.position[tree_.parent[p]], tree_.position[tree_.sibling(s)]);
  }

  // The cheapest way to take segment s out of a collision: remove its subtree and splice its
  // parent bifurcation out, or, when that splice would cross an obstacle, prune both children of
  // the bifurcation so it becomes a terminal. Returns (terminals lost, segment, prune node).
  struct Removal {
    std::int32_t lost, segment, prune;
    bool operator<(const Removal& o) const { return std::tie(lost, segment, prune) < std::tie(o.lost, o.segment, o.prune); }
  };
  // True if segment s, with ends a–e, clears every vessel more than two segments away from it
  // (radii with 1 % margin, as the physics re-solve after a repair shifts them slightly).
  bool capsuleClear(std::int32_t s, const Vec3& a, const Vec3& e, VesselIndex& index) const {
    const double rs = 1.01 * tree_.radius[s];
    return !overlapsOtherVessel(
        tree_, s, a, e, rs, [&](auto&& f) { index.forEachNearVessel(a, e, rs, 1.01, f); }, [&](std::int32_t y) { return 1.01 * tree_.radius[y]; });
  }

  // Pulls terminal segment s back towards its bifurcation until it clears every vessel; false if
  // even the shortest length collides. Any part of a clear segment is clear of obstacles.
  bool retract(std::int32_t s, VesselIndex& index) {
    if (!tree_.isTerminal(s)) return false;
    const Vec3 a = tree_.position[tree_.parent[s]], end = tree_.position[s];
    const double len = distance(a, end);
    const auto clear_at = [&](double f) { return capsuleClear(s, a, a + (end - a) * f, index); };
    const double f_min = std::min(1.0, std::max(2 * min_length_, minLength(s)) / len);
    if (!clear_at(f_min)) return false;
    double lo = f_min, hi = 1.0;
    for (int i = 0; i < 30; ++i) {
      const double mid = 0.5 * (lo + hi);
      (clear_at(mid) ? lo : hi) = mid;
    }
    tree_.position[s] = a + (end - a) * lo;
    tree_.length[s] = distance(a, tree_.position[s]);
    index.insert(tree_, s);
    return true;
  }

  // Moves node v by d if every segment meeting at v stays long enough, clear of obstacles and
  // clear of other vessels; restores it otherwise.
  bool tryMove(std::int32_t v, const Vec3& d, VesselIndex& index) {
    const Vec3 old = tree_.position[v];
    tree_.position[v] = old + d;
    std::int32_t segs[3] = {v, tree_.child0[v], tree_.child1[v]};
    bool ok = true;
    for (auto sg : segs) {
      if (sg < 0 || !ok) continue;
      const Vec3& a = tree_.position[tree_.parent[sg]];
      const Vec3& e = tree_.position[sg];
      ok = distance(a, e) >= minLength(sg) && paths_.segmentClear(a, e) && capsuleClear(sg, a, e, index);
    }
    if (!ok) {
      tree_.position[v] = old;
      return false;
    }
    for (auto sg : segs)
      if (sg >= 0) {
        tree_.length[sg] = distance(tree_.position[tree_.parent[sg]], tree_.position[sg]);
        index.insert(tree_, sg);
      }
    return true;
  }

  // Separates a colliding pair by moving one end node of either vessel away from the other by
  // the overlap (scaled by how much the closest point follows that node); the thinner vessel's
  // nodes are tried first. This keeps trunk collisions from costing whole branches.
  bool separate(std::int32_t x, std::int32_t y, VesselIndex& index) {
    if (tree_.radius[x] > tree_.radius[y]) std::swap(x, y);
    double sx, sy;
    const Vec3 x0 = tree_.position[tree_.parent[x]], x1 = tree_.position[x];
    const Vec3 y0 = tree_.position[tree_.parent[y]], y1 = tree_.position[y];
    const double d = segmentSegmentDistance(x0, x1, y0, y1, sx, sy);
    const Vec3 cx = x0 + (x1 - x0) * sx, cy = y0 + (y1 - y0) * sy;
    Vec3 n = cx - cy;
    if (norm(n) < 1e-12 * (tree_.radius[x] + tree_.radius[y])) {
      // Axes cross: push perpendicular to both.
      const Vec3 u = x1 - x0, w = y1 - y0;
      n = Vec3(u.y * w.z - u.z * w.y, u.z * w.x - u.x * w.z, u.x * w.y - u.y * w.x);
      if (norm(n) == 0) return false;
    }
    n = n / norm(n);
    const double overlap = 1.03 * (tree_.radius[x] + tree_.radius[y]) - d;
    struct Move {
      std::int32_t node;
      double weight;
      double sign;
    };
    const Move moves[4] = {{x, sx, 1}, {tree_.parent[x], 1 - sx, 1}, {y, sy, -1}, {tree_.parent[y], 1 - sy, -1}};
    for (const auto& m : moves) {
      if (m.node <= 0 || m.weight < 0.25) continue;
      for (double k : {1.0, 1.5, 2.5})
        if (tryMove(m.node, n * (m.sign * k * overlap / m.weight), index)) return true;
    }
    return false;
  }

  // The shortest segment s may be in the solved tree.
  double minLength(std::int32_t s) const { return std::max(min_length_, opt_.min_length_ratio * tree_.radius[s] * 1.01); }

  // Segments of the solved tree shorter than min_length_ratio × radius.
  std::vector<std::int32_t> shortSegments() const {
    std::vector<std::int32_t> out;
    if (!(opt_.min_length_ratio > 0)) return out;
    for (std::int32_t s = 1; s < tree_.nodeCount(); ++s)
      if (tree_.length[s] < opt_.min_length_ratio * tree_.radius[s]) out.push_back(s);
    return out;
  }

  // A segment that thickened past the ratio since it was made: slide its distal bifurcation out
  // along it (or towards its children), or its proximal one back, to 1.05–1.5 × the minimum.
  bool lengthen(std::int32_t s, VesselIndex& index) {
    const auto P = tree_.parent[s];
    const Vec3 a = tree_.position[P], e = tree_.position[s];
    const double len = distance(a, e);
    if (!(len > 0)) return false;
    const Vec3 u = (e - a) / len;
    Vec3 w = u;
    if (!tree_.isTerminal(s)) {
      const Vec3 m = (tree_.position[tree_.child0[s]] + tree_.position[tree_.child1[s]]) * 0.5 - e;
      if (norm(m) > 0) w = m / norm(m);
    }
    for (double f : {1.05, 1.25, 1.5}) {
      const double grow = f * opt_.min_length_ratio * tree_.radius[s] - len;
      if (tryMove(s, u * grow, index) || (!tree_.isTerminal(s) && tryMove(s, w * grow, index))) return true;
      if (P > 0 && tryMove(P, u * -grow, index)) return true;
    }
    // Blocked straight ahead (a wall, an obstacle, a neighbour): the distal node on cones of 20°
    // and 40° around the segment's direction.
    Vec3 p1 = cross(u, std::abs(u.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0));
    p1 = p1 / norm(p1);
    const Vec3 p2 = cross(u, p1);
    for (double f : {1.1, 1.3})
      for (double theta : {20.0, 40.0})
        for (int i = 0; i < 8; ++i) {
          const double t = theta * std::numbers::pi / 180, phi = 2 * std::numbers::pi * i / 8;
          const Vec3 d = u * std::cos(t) + (p1 * std::cos(phi) + p2 * std::sin(phi)) * std::sin(t);
          if (tryMove(s, a + d * (f * opt_.min_length_ratio * tree_.radius[s]) - e, index)) return true;
        }
    // A sibling or child as short: either end away from every end it is too close to.
    return spreadEitherEnd(tree_, s, opt_.min_length_ratio, [&](std::int32_t v, const Vec3& q) { return tryMove(v, q - tree_.position[v], index); });
  }

  Removal removalOf(std::int32_t s) const {
    const auto p = tree_.parent[s];
    if (spliceClear(s)) return {tree_.terminals[s], s, -1};
    return {tree_.terminals[p] - 1, -1, p};
  }

  // Records what the demand holds, so that the repair recomputes it only around what differs.
  void perfuseAt(const Vec3& terminal) {
    perfuse(map_, sampler_, terminal, scratch_);
    perfused_.push_back(terminal);
  }

  // Demand as if only the current terminals had been perfused, in the order they were added
  // (node order: a repair keeps the nodes' order). Only the neighbourhoods of the terminals
  // removed, moved or made since the last perfusion are recomputed, unless they are so many that
  // the parallel pass over the whole map is cheaper. Either way the same bits.
  void recomputeDemand() {
    std::vector<Vec3> terminals;
    terminals.reserve(std::size_t(tree_.terminalCount()));
    for (std::int32_t i = 1; i < tree_.nodeCount(); ++i)
      if (tree_.isTerminal(i)) terminals.push_back(tree_.position[i]);
    const auto before = [](const Vec3& a, const Vec3& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); };
    auto now = terminals;
    std::sort(perfused_.begin(), perfused_.end(), before);
    std::sort(now.begin(), now.end(), before);
    std::vector<Vec3> changed;
    std::set_symmetric_difference(perfused_.begin(), perfused_.end(), now.begin(), now.end(), std::back_inserter(changed), before);
    if (4 * changed.size() > terminals.size())
      sampler_ = perfusedDemand(map_, terminals);
    else
      reperfuse(map_, sampler_, changed, terminals);
    perfused_ = std::move(terminals);
  }

  // Each bifurcation was placed for the radii of its day; the vessels around it have thickened
  // since. A few sweeps move every bifurcation to the weighted Fermat point of its three
  // neighbours for the present radii (Weiszfeld's iteration on Σ r^λ l^μ), a move kept only when
  // every constraint of growth still holds, then re-solve the radii. Each move lowers the cost
  // at fixed radii, and shorter vessels lower the resistance and so every radius.
  void relaxBifurcations() {
    if (tree_.segmentCount() < 3) return;
    const double lambda = params_.cost_radius_exponent, mu = params_.cost_length_exponent;
    VesselIndex index(tree_, Vec3(0, 0, 0), map_.extentMm());
    for (int sweep = 0; sweep < opt_.relax_sweeps; ++sweep) {
      // The last sweep's solve changed the radii, and each of its moves appended three segments:
      // rebuilt, the index holds each segment once, filed by its present radius.
      if (sweep > 0) index.rebuild(tree_);
      std::int64_t moved = 0;
      for (std::int32_t v = 1; v < tree_.nodeCount(); ++v) {
        if (tree_.isTerminal(v)) continue;
        const std::int32_t seg[3] = {v, tree_.child0[v], tree_.child1[v]};
        const Vec3 x[3] = {tree_.position[tree_.parent[v]], tree_.position[tree_.child0[v]], tree_.position[tree_.child1[v]]};
        double w[3];
        for (int j = 0; j < 3; ++j) w[j] = std::pow(tree_.radius[seg[j]], lambda);
        const auto cost = [&](const Vec3& b) {
          double c = 0;
          for (int j = 0; j < 3; ++j) c += w[j] * std::pow(distance(b, x[j]), mu);
          return c;
        };
        const Vec3 b0 = tree_.position[v];
        Vec3 b = b0;
        for (int it = 0; it < 20; ++it) {
          Vec3 num;
          double den = 0;
          for (int j = 0; j < 3; ++j) {
            const double l = std::max(distance(b, x[j]), 1e-12);
            const double k = w[j] * mu * std::pow(l, mu - 2);  // ∂/∂b of w l^μ = k (b − x)
            num += x[j] * k;
            den += k;
          }
          if (!(den > 0)) break;
          const Vec3 next = num / den;
          const bool done = distance(next, b) < 1e-6 * min_length_;
          b = next;
          if (done) break;
        }
        if (!(cost(b) < cost(b0) * (1 - 1e-9))) continue;
        for (double f : {1.0, 0.5, 0.25})
          if (tryMove(v, (b - b0) * f, index)) {
            ++moved;
            break;
          }
      }
      report_.relaxed_bifurcations += moved;
      solveTree(tree_, params_);
      if (moved == 0) break;
    }
  }

  // Removes the branches that still collide in the exact final tree and regrows as many
  // terminals, until no pair is left.
  void repair(const ProgressFn& progress) {
    for (int round = 0; round < opt_.max_repair_rounds; ++round) {
      std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
      if (opt_.avoid_intersections) pairs = intersectingPairs(tree_, Vec3(0, 0, 0), map_.extentMm());
      const auto too_short = shortSegments();
      if (pairs.empty() && too_short.empty()) return;
      ++report_.repair_rounds;
      std::vector<std::int32_t> remove, prune;
      VesselIndex index(tree_, Vec3(0, 0, 0), map_.extentMm());
      std::int64_t retracted = 0, moved = 0;
      for (const auto& [x, y] : pairs) {
        // Cheapest first: retract a terminal (the thinner side first), move a node, and only
        // then remove a small branch.
        const bool x_thin = tree_.radius[x] <= tree_.radius[y];
        if (retract(x_thin ? x : y, index) || retract(x_thin ? y : x, index)) {
          ++retracted;
          continue;
        }
        if (separate(x, y, index)) {
          ++moved;
          continue;
        }
        const Removal r = std::min(removalOf(x), removalOf(y));
        if (r.lost > kMaxRepairShare * double(opt_.terminals)) continue;  // left and reported
        if (r.segment >= 0)
          remove.push_back(r.segment);
        else
          prune.push_back(r.prune);
      }
      for (const auto s : too_short) {
        if (tree_.length[s] >= opt_.min_length_ratio * tree_.radius[s]) continue;  // lengthened with a neighbour
        if (lengthen(s, index)) {
          ++moved;
          continue;
        }
        // A terminal goes with its bifurcation. A trunk merges with its larger child when the
        // smaller child's subtree goes, or with its parent when its sibling's does, whichever
        // loses fewer terminals: along a trunk of short segments the side branch to lose is
        // often the small one just above.
        Removal r = removalOf(s);
        if (!tree_.isTerminal(s)) {
          r = std::min(removalOf(tree_.child0[s]), removalOf(tree_.child1[s]));
          if (tree_.parent[s] > 0) r = std::min(r, removalOf(tree_.sibling(s)));
        }
        if (r.lost > kMaxRepairShare * double(opt_.terminals)) continue;  // left and reported
        if (r.segment >= 0)
          remove.push_back(r.segment);
        else
          prune.push_back(r.prune);
      }
      for (auto* v : {&remove, &prune}) {
        std::sort(v->begin(), v->end());
        v->erase(std::unique(v->begin(), v->end()), v->end());
      }
      report_.retracted_terminals += retracted;
      report_.moved_nodes += moved;
      if (remove.empty() && prune.empty()) {
        if (retracted + moved == 0) return;  // nothing cheap left to do
        solveTree(tree_, params_);           // lengths changed: radii follow
        continue;
      }
      const auto before = tree_.terminalCount();
      tree_.removeSubtrees(remove, prune);
      // A spliced-out bifurcation leaves a straight segment that may cross an obstacle.
      for (bool again = true; again && tree_.segmentCount() > 0;) {
        std::vector<std::int32_t> blocked;
        for (std::int32_t s = 1; s < tree_.nodeCount(); ++s)
          if (!paths_.segmentClear(tree_.position[tree_.parent[s]], tree_.position[s])) blocked.push_back(s);
        again = !blocked.empty();
        if (again) tree_.removeSubtrees(blocked);
      }
      report_.repaired_terminals += before - tree_.terminalCount();
      recomputeDemand();
      solveTree(tree_, params_);
      rel_.assign(tree_.nodeCount(), 1.0);
      if (tree_.segmentCount() > 0) {
        const double r_root = tree_.radius[tree_.rootSegment()];
        for (std::int32_t s = 1; s < tree_.nodeCount(); ++s) rel_[s] = tree_.radius[s] / r_root;
        root_history_[tree_.terminalCount()] = r_root;
      }
      index_.refresh(tree_, true);
      growUntil(opt_.terminals, progress);
      solveTree(tree_, params_);
    }
  }

  const DemandMap& map_;
  const ClearPaths paths_;
  const GrowthOptions& opt_;
  GrowthReport& report_;
  PhysicsParameters params_;
  DemandSampler sampler_;
  SegmentIndex index_;
  Rng rng_;
  VascularTree tree_;
  std::vector<double> rel_{1.0};      // radius / root radius, refreshed along every new path
  std::vector<double> root_history_;  // root radius when the tree had n terminals
  std::vector<std::pair<std::int64_t, double>> scratch_;
  std::vector<Vec3> perfused_;  // the terminals the sampler's demand holds, in perfusion order
  double min_length_ = 0;
};

}  // namespace

VascularTree growVascuSynth(const DemandMap& map, const GrowthOptions& options, GrowthReport& report, const ProgressFn& progress) {
  Grower g(map, options, report);
  return g.run(progress);
}

}  // namespace angiosynth
