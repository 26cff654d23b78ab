#include "grow/colonisation/grower.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/rng.hpp"
#include "grow/common/neighbourhood_count.hpp"
#include "core/point_hash.hpp"

namespace angiosynth {

double symmetricMurrayAngle(double kappa) { return std::acos(std::clamp(std::pow(2.0, 2.0 / kappa - 1.0), -1.0, 1.0)); }

MurrayLaw colonisationLaw(const ColonisationOptions& o) { return {o.murray_exponent, o.murray_band_edges, o.murray_band_exponents}; }

double lateralMurrayAngle(double rp, double rb, double kappa) {
  // A parent is at least as thick as a symmetric split of two such branches (a chain of leaves'
  // radius would otherwise leave no continuation and an angle of 0).
  rp = std::max(rp, rb * std::pow(2.0, 1.0 / kappa));
  const double rc_k = std::pow(rp, kappa) - std::pow(rb, kappa);
  const double rc = rc_k > 0 ? std::pow(rc_k, 1.0 / kappa) : 0.0;
  const double c = (std::pow(rp, 4) + std::pow(rb, 4) - std::pow(rc, 4)) / (2 * rp * rp * rb * rb);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

std::vector<double> colonisationScales(const ColonisationOptions& o) {
  std::vector<double> sigma;
  double s = o.sigma0;
  for (const auto& st : o.stages)
    for (int t = 0; t < st.steps; ++t) {
      sigma.push_back(s);
      s += st.delta_sigma;
    }
  const double last = sigma.empty() ? 1.0 : sigma.back();
  for (auto& v : sigma) v = last / v;
  return sigma;
}

namespace {

constexpr double kDeg = std::numbers::pi / 180;

// A unit vector perpendicular to e (in the plane z = const when e is).
Vec3 perpendicular(const Vec3& e) {
  const Vec3 a = std::abs(e.z) < 0.9 && (std::abs(e.x) > 1e-12 || std::abs(e.y) > 1e-12) ? Vec3(-e.y, e.x, 0) : cross(e, Vec3(1, 0, 0));
  return unit(a);
}

// Dominant eigenvector of a symmetric 3×3 matrix (power iteration from a fixed start).
Vec3 dominantAxis(const double m[3][3]) {
  Vec3 v(0.8017, 0.5345, 0.2673);
  for (int it = 0; it < 60; ++it) {
    const Vec3 w(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                 m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z);
    const double n = norm(w);
    if (!(n > 0)) return Vec3(0, 0, 0);
    v = w / n;
  }
  return v;
}

// One system of trees (arterial or venous): its nodes, its drains and their indices.
struct System {
  bool vein = false;
  std::vector<Vec3> pos, dir;  // dir: unit direction of the edge ending at the node (root: its heading)
  std::vector<std::int32_t> parent, child0, child1, root_of;
  std::vector<double> leaf_radius;  // the radius a leaf carries
  std::vector<double> leaf_rk;      // leaf_radius^κ
  std::vector<double> rk;           // Σ leaf_radius^κ over the leaves below: the edge's radius^κ (Murray)
  std::vector<double> radius;       // exact Murray radii, set by finishRadii()
  std::vector<std::int32_t> roots;  // the root nodes
  double kappa = 2.55;
  MurrayLaw law;           // κ, or κ by band of parent radius
  PointHash nodes;         // cells of the perception distance
  PointHash close;         // cells of the satisfaction distance: "is a node this close?"
  PointHash drains;        // cells of the drain spacing
  NeighbourhoodCount far;  // cells of the longest query distance: most "no node near" answers in one read
  std::vector<Vec3> drain;
  std::vector<std::int32_t> born;  // the step a drain appeared
  // A drain's nearest node within the perception distance (−1: none), found when it was made,
  // and the node count then: still exact while the step and the nodes are the same, and in the
  // same step it settles satisfaction by the nodes made before.
  std::vector<std::int32_t> near, near_count;
  bool flat = false;
  std::vector<std::int32_t> cone_stamp;  // per node: the step its perception bounds were computed
  std::vector<double> cos_lo, cos_hi;
  std::vector<double> lateral_angle;  // an inter-node's Murray angle of a lateral branch, same step

  System(const Vec3& lo, const Vec3& hi, double node_cell, double close_cell, double drain_cell, bool is_flat)
      : nodes(lo, hi, node_cell, is_flat),
        close(lo, hi, close_cell, is_flat),
        drains(lo, hi, drain_cell, is_flat),
        flat(is_flat),
        lo_(lo),
        hi_(hi),
        scale_(1) {}

  // The grids' cells follow the step's lengths (× σ_T/σ_t, up to 3× the last step's early in a
  // run): a query then scans a few cells, not dozens. Queries answer the same on any cells.
  // `reach`: the longest distance a "node within" question asks at this step; the far grid is
  // rebuilt when it no longer covers it or when it is 20 % too coarse.
  void rescale(double node_cell, double close_cell, double drain_cell, double k, double reach) {
    if (!(far_reach_ >= reach && far_reach_ <= 1.2 * reach)) {
      far_reach_ = reach;
      far = NeighbourhoodCount(lo_, hi_, reach, flat);
      for (const auto& p : pos) far.insert(p);
    }
    if (std::abs(std::log(k / scale_)) < std::log(1.25)) return;
    scale_ = k;
    nodes = PointHash(lo_, hi_, node_cell * k, flat);
    close = PointHash(lo_, hi_, close_cell * k, flat);
    drains = PointHash(lo_, hi_, drain_cell * k, flat);
    for (std::size_t i = 0; i < pos.size(); ++i) nodes.insert(pos[i], std::int32_t(i)), close.insert(pos[i], std::int32_t(i));
    for (std::size_t d = 0; d < drain.size(); ++d) drains.insert(drain[d], std::int32_t(d));
  }
  Vec3 lo_, hi_;
  double scale_, far_reach_ = 0;
  double last_leaf_r_ = -1, last_leaf_rk_ = 0;

  double radiusOf(std::int32_t i) const { return std::pow(rk[std::size_t(i)], 1.0 / kappa); }

  std::int32_t add(const Vec3& p, std::int32_t par, const Vec3& d, double leaf_r, std::int32_t root) {
    const auto id = static_cast<std::int32_t>(pos.size());
    pos.push_back(p);
    dir.push_back(d);
    parent.push_back(par);
    child0.push_back(-1);
    child1.push_back(-1);
    root_of.push_back(root);
    // Every leaf of a step has the same radius: its power is taken once.
    if (leaf_r != last_leaf_r_) last_leaf_r_ = leaf_r, last_leaf_rk_ = std::pow(leaf_r, kappa);
    const double own = last_leaf_rk_;
    leaf_radius.push_back(leaf_r);
    leaf_rk.push_back(own);
    rk.push_back(own);
    if (par < 0) roots.push_back(id);
    if (par >= 0) {
      // Murray's law in r^κ is additive: the new leaf adds its share to every ancestor, and a
      // leaf that becomes a parent no longer counts its own.
      const double delta = child0[par] < 0 ? own - leaf_rk[std::size_t(par)] : own;
      (child0[par] < 0 ? child0[par] : child1[par]) = id;
      for (std::int32_t a = par; a >= 0; a = parent[a]) rk[a] += delta;
    }
    nodes.insert(p, id);
    close.insert(p, id);
    far.insert(p);
    return id;
  }
  // `nearest`: its nearest node within this step's perception distance, or −2 (not known).
  void addDrain(const Vec3& p, std::int32_t step, std::int32_t nearest = -2) {
    const auto id = static_cast<std::int32_t>(drain.size());
    drain.push_back(p);
    born.push_back(step);
    near.push_back(nearest);
    near_count.push_back(std::int32_t(pos.size()));
    drains.insert(p, id);
  }
  // True if a node lies within r (r at most a few cells of `close`, and at most the reach).
  bool nodeWithin(const Vec3& p, double r) const {
    if (!far.mayBeNear(p)) return false;
    const double r2 = r * r;
    return (r > 2 * close.cell() ? nodes : close).anyNear(p, r, [&](std::int32_t id) {
      const Vec3 v = pos[id] - p;
      return dot(v, v) < r2;
    });
  }
  // Nearest node within r (at most the reach; ties: the smaller id), or -1.
  std::int32_t nearestNode(const Vec3& p, double r) const {
    if (!far.mayBeNear(p)) return -1;
    return nodes.nearest(p, r, [&](std::int32_t id) {
      const Vec3 v = pos[id] - p;
      return dot(v, v);
    });
  }
  // The cached nearest node of drain k, if still exact at `step`.
  bool knowsNearest(std::size_t k, std::int32_t step) const { return near[k] != -2 && born[k] == step && near_count[k] == std::int32_t(pos.size()); }
  bool anyDrainWithin(const Vec3& p, double r) const {
    const double r2 = r * r;
    return drains.anyNear(p, r, [&](std::int32_t id) {
      const Vec3 v = drain[id] - p;
      return dot(v, v) < r2;
    });
  }
  // Exact Murray radii from the leaves up (children come after their parent), once at the end.
  void finishRadii() {
    radius.assign(pos.size(), 0);
    for (std::size_t k = pos.size(); k-- > 0;) {
      const auto a = child0[k], b = child1[k];
      if (a < 0)
        radius[k] = leaf_radius[k];
      else if (b < 0)
        radius[k] = radius[a];
      else
        radius[k] = law.parentRadius(radius[a], radius[b]);
    }
  }
  // Keeps the drains listed (ascending), renumbered from 0: ids stay small and storage warm.
  void keepDrains(const std::vector<std::int32_t>& keep) {
    std::size_t n = 0;
    for (auto d : keep) {
      drain[n] = drain[std::size_t(d)];
      near[n] = near[std::size_t(d)];
      near_count[n] = near_count[std::size_t(d)];
      born[n++] = born[std::size_t(d)];
    }
    drain.resize(n);
    born.resize(n);
    near.resize(n);
    near_count.resize(n);
    drains.clear();
    for (std::size_t d = 0; d < n; ++d) drains.insert(drain[d], std::int32_t(d));
  }
};

// One step's lengths (a stage's, × σ_T/σ_t) and index: passed along, because the veins of step t
// grow while the candidates of step t + 1 are tested against the arteries.
struct StepScale {
  const ColonisationStage* st = nullptr;
  std::int32_t index = 0;
  double k = 1;  // σ_T/σ_t
  double len = 0, delta = 0, sat = 0, spacing = 0, co2 = 0, terminal_radius = 0;
};

class Grower {
 public:
  Grower(const ColonisationOptions& o, GrowthReport& report, ColonisationReport& cr)
      : o_(o),
        report_(report),
        cr_(cr),
        world_(*o.world),
        art_(world_.lo(), world_.hi(), cell(o, 0), cell(o, 1), cell(o, 2), world_.dimension() == 2),
        ven_(world_.lo(), world_.hi(), cell(o, 0), cell(o, 1), cell(o, 2), world_.dimension() == 2) {
    art_.vein = false;
    ven_.vein = true;
    art_.kappa = ven_.kappa = o.murray_exponent;
    art_.law = ven_.law = colonisationLaw(o);
    symmetric_angle_ = symmetricMurrayAngle(o.murray_exponent);
    for (const auto& st : o.stages) reach_ = std::max({reach_, st.perception_distance, st.co2_distance, st.satisfaction_distance});
    for (std::size_t k = 0; k < o.roots.size(); ++k) {
      const auto& r = o.roots[k];
      auto& s = r.vein ? ven_ : art_;
      const double leaf = o.stages.front().terminal_radius;
      if (!r.stump) {
        s.add(r.position, -1, unit(r.direction), leaf, std::int32_t(k));
        continue;
      }
      const auto& t = *r.stump;
      std::vector<std::int32_t> id(std::size_t(t.nodeCount()), -1);
      for (auto i : t.topDownOrder()) {
        const bool root = t.isRoot(i);
        const Vec3 d = root ? (t.child0[i] >= 0 ? t.position[t.child0[i]] - t.position[i] : r.direction) : t.position[i] - t.position[t.parent[i]];
        const double radius = !root && t.child0[i] < 0 && t.radius[i] > 0 ? t.radius[i] : leaf;
        id[std::size_t(i)] = s.add(t.position[i], root ? -1 : id[std::size_t(t.parent[i])], unit(d), radius, std::int32_t(k));
      }
    }
    veins_ = o.veins && !ven_.pos.empty();
  }

  // Step t: (1) candidates meet the arteries, while the veins of step t − 1 grow; (2) candidates
  // meet the veins and become venous drains, while they become arterial drains and the arteries
  // grow; (3) the arteries satisfy drains, which turn into CO₂ sources for the veins. Tasks side
  // by side read and write disjoint state (vein growth with avoid_crossing reads the arteries,
  // so then it takes its turn), and every system sees its state in the order of a plain
  // sequence of steps: the trees are the same on any thread count.
  void run(const ProgressFn& progress) {
    const auto scales = colonisationScales(o_);
    std::vector<StepScale> steps;
    for (const auto& st : o_.stages)
      for (int i = 0; i < st.steps; ++i) {
        const double k = scales[steps.size()];
        StepScale t;
        t.st = &st;
        t.index = std::int32_t(steps.size());
        t.len = st.step * k;
        t.delta = st.perception_distance * k;
        t.sat = st.satisfaction_distance * k;
        t.spacing = st.drain_spacing * k;
        t.co2 = st.co2_distance * k;
        t.terminal_radius = st.terminal_radius * k;
        t.k = k;
        steps.push_back(t);
      }
    std::int64_t arteries_after = 0;  // artery nodes at the end of the step whose veins are pending
    const auto finished = [&](const StepScale& t) {
      cr_.nodes_per_step.push_back(arteries_after + std::int64_t(ven_.pos.size()));
      if (progress) progress(std::int64_t(t.index + 1), std::int64_t(steps.size()));
    };
    for (std::size_t i = 0; i < steps.size(); ++i) {
      StepScale& t = steps[i];
      const StepScale* before = i > 0 ? &steps[i - 1] : nullptr;
      art_.rescale(cell(o_, 0), cell(o_, 1), cell(o_, 2), t.k, reach_ * t.k);
      if (before && !o_.avoid_crossing) {
        tbb::parallel_invoke([&] { growVeins(*before); }, [&] { meetArteries(t); });
      } else {
        if (before) growVeins(*before);
        meetArteries(t);
      }
      if (before) finished(*before);
      ven_.rescale(cell(o_, 0), cell(o_, 1), cell(o_, 2), t.k, reach_ * t.k);
      report_.candidates += std::int64_t(candidates_.size());
      tbb::parallel_invoke(
          [&] {
            meetVeins(t);
            admitVeins(t);
          },
          [&] {
            admitArteries(t);
            grow(art_, t);
          });
      for (const System* s : {&art_, &ven_})
        for (auto r : s->roots) max_radius_ = std::max(max_radius_, s->radiusOf(r));
      satisfy(art_, t, veins_ ? &ven_ : nullptr);
      arteries_after = std::int64_t(art_.pos.size());
    }
    if (!steps.empty()) {
      growVeins(steps.back());
      finished(steps.back());
    }
  }

  // The trees, one per root in the order of the options' roots.
  std::vector<VascularTree> trees() {
    art_.finishRadii();
    ven_.finishRadii();
    std::vector<VascularTree> out(o_.roots.size());
    for (const System* s : {&art_, &ven_}) {
      for (std::size_t r = 0; r < s->pos.size(); ++r) {
        if (s->parent[r] >= 0) continue;
        auto& t = out[std::size_t(s->root_of[r])];
        std::vector<std::int32_t> id(s->pos.size(), -1), queue{std::int32_t(r)};
        id[r] = t.addNode(s->pos[r], -1);
        for (std::size_t q = 0; q < queue.size(); ++q)
          for (auto c : {s->child0[queue[q]], s->child1[queue[q]]}) {
            if (c < 0) continue;
            id[c] = t.addNode(s->pos[c], id[queue[q]]);
            t.radius[id[c]] = s->radius[c];
            queue.push_back(c);
          }
      }
    }
    return out;
  }

 private:
  // Cells (0) of the node grid: half the smallest perception distance (the ring search of the
  // nearest node stops after a few small cells when a node is close); (1) of the near-node grid:
  // the smallest satisfaction distance; (2) of the drain grid: half the perception distance, or
  // the spacing if larger (live drains are sparse: a few fuller cells scan faster than many
  // empty ones).
  static double cell(const ColonisationOptions& o, int which) {
    double c = INFINITY;
    for (const auto& st : o.stages)
      c = std::min(c, which == 0   ? st.perception_distance / 2
                      : which == 1 ? st.satisfaction_distance
                                   : std::max(st.drain_spacing, st.perception_distance / 2));
    return std::max(c, 1e-6);
  }

  // The centreline a–b inside the world: convex shapes by its end, masks voxel by voxel (every
  // voxel the segment crosses is inside; sampling at fractions of a voxel can cut a corner).
  bool inside(const Vec3& a, const Vec3& b) const {
    if (world_.shape() != DomainShape::Mask) return world_.depth(b) > 0;  // a is a node (or a root on the border)
    return world_.depth(b) > 0 && world_.frame().segmentClear(a, b);
  }

  Vec3 sampleDrain(const ColonisationStage& st, Rng&& rng) const {
    const GrowthDomain& d = *st.drains;
    if (st.source == DrainSource::Volume) return d.sample(rng);
    for (int tries = 0;; ++tries) {  // surface: rejection to the shell of depth ≤ surface_depth
      const Vec3 p = d.sample(rng);
      if (d.depth(p) <= st.surface_depth || tries >= 1000) return p;
    }
  }

  // Moves a surface-mode node back into the shell along the depth gradient.
  Vec3 toShell(const ColonisationStage& st, Vec3 p) const {
    if (st.source != DrainSource::Surface) return p;
    const double h = world_.frame().voxel_mm / 2;
    for (int it = 0; it < 3; ++it) {
      const double dp = world_.depth(p);
      if (dp <= st.surface_depth) break;
      Vec3 g((world_.depth(p + Vec3(h, 0, 0)) - world_.depth(p - Vec3(h, 0, 0))) / (2 * h),
             (world_.depth(p + Vec3(0, h, 0)) - world_.depth(p - Vec3(0, h, 0))) / (2 * h),
             world_.dimension() == 2 ? 0.0 : (world_.depth(p + Vec3(0, 0, h)) - world_.depth(p - Vec3(0, 0, h))) / (2 * h));
      const double n = norm(g);
      if (!(n > 0)) break;
      p = p - g / n * (dp - st.surface_depth / 2);
    }
    return p;
  }

  // True if a new vessel a–b of radius r would come closer to a vessel of either system than
  // their radii allow (vessels meeting at `from` excluded).
  bool crosses(const System& own, std::int32_t from, const Vec3& a, const Vec3& b, double r) const {
    if (!o_.avoid_crossing) return false;
    bool hit = false;
    for (const System* s : {&art_, &ven_}) {
      const double reach = distance(a, b) + max_edge_ + r + max_radius_;
      s->nodes.forEachNear((a + b) * 0.5, reach, [&](std::int32_t y) {
        if (hit || s->parent[y] < 0) return;
        if (s == &own && (y == from || s->parent[y] == from || y == own.parent[from])) return;
        hit = segmentSegmentDistance(a, b, s->pos[s->parent[y]], s->pos[y]) < r + s->radiusOf(y);
      });
    }
    return hit;
  }

  // Which node perceives each live drain (its closest node, if the drain lies in that node's
  // perception volume), grouped by node.
  std::vector<std::pair<std::int32_t, std::int32_t>> assign(System& s, const StepScale& t) {
    const ColonisationStage& st = *t.st;
    const double half = st.perception_angle * kDeg / 2, cos_half = std::cos(half);
    std::vector<std::int32_t> owner(s.drain.size(), -1);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.drain.size(), 512), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t k = b.begin(); k != b.end(); ++k) owner[k] = s.knowsNearest(k, t.index) ? s.near[k] : s.nearestNode(s.drain[k], t.delta);
    });
    // Perception bounds of the nodes that are nearest to some drain, computed once per step.
    s.cone_stamp.resize(s.pos.size(), -1);
    s.cos_lo.resize(s.pos.size());
    s.cos_hi.resize(s.pos.size());
    s.lateral_angle.resize(s.pos.size());
    std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
    for (std::size_t k = 0; k < s.drain.size(); ++k) {
      const auto j = owner[k];
      if (j < 0) continue;
      if (s.cone_stamp[j] != t.index) {
        s.cone_stamp[j] = t.index;
        s.cos_lo[j] = s.cos_hi[j] = 2.0;  // perceives nothing
        if (s.child0[j] < 0) {
          s.cos_lo[j] = cos_half;
          s.cos_hi[j] = 1.0;
        } else if (st.lateral && s.child1[j] < 0 && s.parent[j] >= 0) {
          const double alpha = s.lateral_angle[j] = lateralMurrayAngle(s.radiusOf(j), t.terminal_radius, s.law.exponentAt(s.radiusOf(j)));
          s.cos_lo[j] = std::cos(std::min(std::numbers::pi, alpha + half));
          s.cos_hi[j] = std::cos(std::max(0.0, alpha - half));
        }
      }
      const Vec3 v = s.drain[k] - s.pos[j];
      const double d = norm(v);
      const double c = d > 0 ? dot(v, s.dir[j]) / d : -2.0;
      if (c >= s.cos_lo[j] && c <= s.cos_hi[j]) pairs.emplace_back(j, std::int32_t(k));
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
  }

  double spread(const std::vector<Vec3>& u, const Vec3& mean_dir, SpreadStatistic stat) const {
    double sum = 0, sum2 = 0;
    for (const auto& v : u) {
      const double a = std::acos(std::clamp(dot(v, mean_dir), -1.0, 1.0));
      sum += a;
      sum2 += a * a;
    }
    const double n = double(u.size()), mean = sum / n;
    return stat == SpreadStatistic::RootMeanSquare ? std::sqrt(sum2 / n) : std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  }

  struct Pending {
    std::int32_t from;
    Vec3 position, direction;
  };
  enum class Move : char { None, Bifurcation, Elongation, Lateral };
  // What one perceiving node does this step: up to two new nodes, and the tries refused.
  struct Decision {
    Pending add[2];
    int added = 0, outside = 0, crossing = 0;
    Move move = Move::None;
  };

  // A new node of s from `from` along dir, unless it leaves the world or crosses a vessel.
  bool tryAdd(const System& s, const StepScale& t, std::int32_t from, Vec3 dir, Decision& d) const {
    Vec3 p = toShell(*t.st, s.pos[from] + dir * t.len);
    if (!inside(s.pos[from], p)) {
      ++d.outside;
      return false;
    }
    if (crosses(s, from, s.pos[from], p, t.terminal_radius)) {
      ++d.crossing;
      return false;
    }
    d.add[d.added++] = {from, p, unit(p - s.pos[from])};
    return true;
  }

  // Node j's response to the drains it perceives (pairs [a, b)): it reads the step's starting
  // state only, so the nodes decide in parallel.
  Decision decide(const System& s, const StepScale& t, const std::vector<std::pair<std::int32_t, std::int32_t>>& pairs, std::size_t a,
                  std::size_t b) const {
    const ColonisationStage& st = *t.st;
    Decision d;
    const std::int32_t j = pairs[a].first;
    const Vec3 pj = s.pos[j], e = s.dir[j];
    thread_local std::vector<Vec3> u;
    u.clear();
    Vec3 m(0, 0, 0), c(0, 0, 0);
    for (std::size_t q = a; q < b; ++q) {
      const Vec3 p = s.drain[pairs[q].second];
      u.push_back(unit(p - pj));
      m += u.back();
      c += p;
    }
    const double n = double(u.size());
    m = unit(m / n);
    if (!(norm(m) > 0)) m = e;
    if (s.child0[j] < 0) {
      // A leaf (not a root): split when the drains spread wider than φ, else elongate.
      if (s.parent[j] >= 0 && u.size() >= 2 && spread(u, m, st.spread) > st.bifurcation_spread * kDeg) {
        c = c / n;
        double cov[3][3] = {};
        for (std::size_t q = 0; q < u.size(); ++q) {
          const Vec3 v = s.drain[pairs[a + q].second] - c;
          for (int r = 0; r < 3; ++r)
            for (int w = 0; w < 3; ++w) cov[r][w] += v[r] * v[w];
        }
        Vec3 w = dominantAxis(cov);
        w = w - e * dot(w, e);
        if (!(norm(w) > 1e-9)) w = m - e * dot(m, e);
        if (!(norm(w) > 1e-9)) w = perpendicular(e);
        w = unit(w);
        const double alpha_s = s.law.banded() ? symmetricMurrayAngle(s.law.exponentAt(s.radiusOf(j))) : symmetric_angle_;
        const Vec3 d1 = e * std::cos(alpha_s) + w * std::sin(alpha_s), d2 = e * std::cos(alpha_s) - w * std::sin(alpha_s);
        if (tryAdd(s, t, j, d1, d) && tryAdd(s, t, j, d2, d)) {
          d.move = Move::Bifurcation;
          return d;
        }
        d.added = 0;
      }
      Vec3 g = e * st.bias + m * (1 - st.bias);
      if (!(norm(g) > 1e-12)) g = e;
      if (tryAdd(s, t, j, unit(g), d)) d.move = Move::Elongation;
    } else if (s.child1[j] < 0) {
      // An inter-node: a lateral branch at the Murray angle, turned toward the drains.
      const double alpha = s.lateral_angle[j];  // a drain in its shell was assigned: set this step
      Vec3 w = m - e * dot(m, e);
      if (!(norm(w) > 1e-9)) return d;
      const Vec3 v = e * std::cos(alpha) + unit(w) * std::sin(alpha);
      Vec3 g = v * st.bias + m * (1 - st.bias);
      if (!(norm(g) > 1e-12)) g = v;
      if (tryAdd(s, t, j, unit(g), d)) d.move = Move::Lateral;
    }
    return d;
  }

  void grow(System& s, const StepScale& t) {
    const auto pairs = assign(s, t);
    std::vector<std::size_t> start;
    for (std::size_t a = 0; a < pairs.size(); ++a)
      if (a == 0 || pairs[a].first != pairs[a - 1].first) start.push_back(a);
    start.push_back(pairs.size());
    std::vector<Decision> decisions(start.size() - 1);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, decisions.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t g = r.begin(); g != r.end(); ++g) decisions[g] = decide(s, t, pairs, start[g], start[g + 1]);
    });
    // Nodes join in the order of their parents: the same tree on any thread count.
    for (const auto& d : decisions) {
      cr_.outside_rejected += d.outside;
      cr_.crossing_rejected += d.crossing;
      cr_.bifurcations += d.move == Move::Bifurcation;
      cr_.elongations += d.move == Move::Elongation;
      cr_.lateral_branches += d.move == Move::Lateral;
      for (int i = 0; i < d.added; ++i) {
        const auto& p = d.add[i];
        s.add(p.position, p.from, p.direction, t.terminal_radius, s.root_of[p.from]);
        max_edge_ = std::max(max_edge_, distance(p.position, s.pos[p.from]));
      }
    }
  }

  // Drains of s within `sat` of one of its nodes are satisfied: removed (an artery's become the
  // veins' CO₂ sources).
  // `delta`: the perception distance, for the nearest vein of each new CO₂ source.
  void satisfy(System& s, const StepScale& t, System* co2) {
    const double sat = t.sat, sat2 = sat * sat, delta = t.delta;
    const int lifetime = t.st->drain_lifetime;
    // A drain made this step knows its nearest node within δ ≥ sat among the nodes before
    // growth, so only the few nodes made since can satisfy it otherwise: they look for drains.
    enum : char { Open = 0, Satisfied = 1, Unknown = 2 };
    std::vector<char> done(s.drain.size(), Unknown);
    auto first_new = std::int32_t(s.pos.size());
    for (std::size_t k = 0; k < s.drain.size(); ++k) {
      if (!(delta >= sat) || s.born[k] != t.index || s.near[k] == -2) continue;
      const auto j = s.near[k];
      done[k] = j >= 0 && dot(s.drain[k] - s.pos[std::size_t(j)], s.drain[k] - s.pos[std::size_t(j)]) < sat2 ? Satisfied : Open;
      first_new = std::min(first_new, s.near_count[k]);
    }
    for (auto n = first_new; n < std::int32_t(s.pos.size()); ++n)
      s.drains.forEachNear(s.pos[std::size_t(n)], sat, [&](std::int32_t d) {
        const Vec3 v = s.drain[std::size_t(d)] - s.pos[std::size_t(n)];
        if (done[std::size_t(d)] == Open && n >= s.near_count[std::size_t(d)] && dot(v, v) < sat2) done[std::size_t(d)] = Satisfied;
      });
    std::vector<std::int32_t> vein_near(co2 ? s.drain.size() : 0, -2);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.drain.size(), 256), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t k = b.begin(); k != b.end(); ++k) {
        if (done[k] == Unknown) done[k] = s.nodeWithin(s.drain[k], sat) ? Satisfied : Open;
        if (done[k] == Satisfied && co2) vein_near[k] = co2->nearestNode(s.drain[k], delta);
      }
    });
    std::vector<std::int32_t> keep;
    for (std::size_t k = 0; k < s.drain.size(); ++k) {
      if (done[k] == Open) {
        if (lifetime <= 0 || t.index - s.born[k] + 1 < lifetime) keep.push_back(std::int32_t(k));  // else expired unsatisfied
        continue;
      }
      if (!s.vein) ++cr_.satisfied;
      if (co2) {
        co2->addDrain(s.drain[k], t.index, vein_near[k]);
        ++cr_.venous_drains;
      }
    }
    s.keepDrains(keep);
  }

  // Oxygen drains go where the tissue is not yet supplied, apart from each other. Candidate q of
  // step t is drawn from its own stream and tested in parallel against the trees and the drains
  // the step began with; the spacing among this step's drains is kept in draw order (admit).
  enum : char { Supplied = 1, Oxygenated = 2, Drained = 4, NearVeinDrain = 8, NearArteryDrain = 16 };

  // Draws the step's candidates and tests them against the arteries. Supplied: an artery within
  // the satisfaction distance; oxygenated: within the CO₂ distance (such tissue makes CO₂, a
  // source for the veins unless a vein drains it). A candidate that may become a drain also finds
  // the node that will perceive it.
  void meetArteries(const StepScale& t) {
    const ColonisationStage& st = *t.st;
    const std::uint64_t stream = Rng::streamKey(o_.seed, o_.sample, Stage::Growth);
    candidates_.resize(std::size_t(st.drains_per_step));
    art_flags_.assign(candidates_.size(), 0);
    art_near_.assign(candidates_.size(), -2);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates_.size(), 64), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t q = b.begin(); q != b.end(); ++q) {
        // ≡ Rng(seed, sample, Growth, 1 + (t << 32) + q): candidate q of step t has a stream of its own
        const Vec3 p = candidates_[q] = sampleDrain(st, Rng::fromKey(stream + 1 + (std::uint64_t(t.index) << 32) + q));
        char f = 0;
        if (art_.nodeWithin(p, t.sat)) {
          f = Supplied;
        } else if (art_.anyDrainWithin(p, t.spacing)) {
          f = NearArteryDrain | (veins_ && art_.nodeWithin(p, t.co2) ? Oxygenated : 0);
        } else {
          const auto j = art_.nearestNode(p, std::max(t.delta, t.co2));
          const Vec3 v = j >= 0 ? art_.pos[std::size_t(j)] - p : Vec3(0, 0, 0);
          const double d2 = j >= 0 ? dot(v, v) : INFINITY;
          if (veins_ && d2 < t.co2 * t.co2) f = Oxygenated;
          art_near_[q] = d2 < t.delta * t.delta ? j : -1;
        }
        art_flags_[q] = f;
      }
    });
  }

  // Tests the candidates that make CO₂ against the veins.
  void meetVeins(const StepScale& t) {
    ven_flags_.assign(candidates_.size(), 0);
    ven_near_.assign(candidates_.size(), -2);
    if (!veins_) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates_.size(), 64), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t q = b.begin(); q != b.end(); ++q) {
        if (!(art_flags_[q] & (Supplied | Oxygenated))) continue;
        const Vec3 p = candidates_[q];
        if (ven_.nodeWithin(p, t.sat))
          ven_flags_[q] = Drained;
        else if (ven_.anyDrainWithin(p, t.spacing))
          ven_flags_[q] = NearVeinDrain;
        else
          ven_near_[q] = ven_.nearestNode(p, t.delta);
      }
    });
  }

  // The candidates become drains in draw order, each apart from those before it (one near a
  // drain the step began with was flagged already, so the test against all drains is the test
  // against this step's). Veins and arteries each keep their own drains.
  void admitVeins(const StepScale& t) {
    if (!veins_) return;
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
      const Vec3 p = candidates_[i];
      if ((art_flags_[i] & (Supplied | Oxygenated)) && !(ven_flags_[i] & (Drained | NearVeinDrain)) && !ven_.anyDrainWithin(p, t.spacing)) {
        ven_.addDrain(p, t.index, ven_near_[i]);
        ++cr_.venous_drains;
      }
    }
  }
  void admitArteries(const StepScale& t) {
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
      const Vec3 p = candidates_[i];
      const char f = art_flags_[i];
      if (f & Supplied) {
        ++report_.rejected_too_close;
        continue;
      }
      if ((f & NearArteryDrain) || art_.anyDrainWithin(p, t.spacing)) continue;
      art_.addDrain(p, t.index, art_near_[i]);
      ++cr_.arterial_drains;
    }
  }

  // The veins grow to their drains and CO₂ sources, which they satisfy.
  void growVeins(const StepScale& t) {
    if (!veins_) return;
    grow(ven_, t);
    satisfy(ven_, t, nullptr);
  }

  const ColonisationOptions& o_;
  GrowthReport& report_;
  ColonisationReport& cr_;
  const GrowthDomain& world_;
  System art_, ven_;
  std::vector<Vec3> candidates_;
  std::vector<char> art_flags_, ven_flags_;
  std::vector<std::int32_t> art_near_, ven_near_;
  double max_edge_ = 0, max_radius_ = 0, symmetric_angle_ = 0;
  double reach_ = 0;    // the longest "node within" distance of any stage (last step's)
  bool veins_ = false;  // the venous system grows (asked for, and it has a root)
};

}  // namespace

std::vector<VascularTree> growColonisation(const ColonisationOptions& o, GrowthReport& report, ColonisationReport& cr, const ProgressFn& progress) {
  Grower g(o, report, cr);
  g.run(progress);
  return g.trees();
}

}  // namespace angiosynth
