#include "grow/colonisation/grower.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/rng.hpp"
#include "grow/common/point_hash.hpp"

namespace angiosynth {

double symmetricMurrayAngle(double kappa) { return std::acos(std::clamp(std::pow(2.0, 2.0 / kappa - 1.0), -1.0, 1.0)); }

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
  std::vector<Vec3> pos, dir;               // dir: unit direction of the edge ending at the node (root: its heading)
  std::vector<std::int32_t> parent, child0, child1, root_of;
  std::vector<double> leaf_radius;           // the radius a leaf carries
  std::vector<double> rk;                    // Σ leaf_radius^κ over the leaves below: the edge's radius^κ (Murray)
  std::vector<double> radius;                // exact Murray radii, set by finishRadii()
  std::vector<std::int32_t> roots;           // the root nodes
  double kappa = 2.55;
  PointHash nodes;   // cells of the perception distance
  PointHash close;   // cells of the satisfaction distance: "is a node this close?"
  PointHash drains;  // cells of the drain spacing
  PointHash fresh;   // the drains added in this step's sampling, same cells
  std::vector<Vec3> drain;
  std::vector<std::int32_t> born;           // the step a drain appeared
  // A drain's nearest node within the perception distance (−1: none), found when it was made,
  // and the node count then: still exact while the step and the nodes are the same.
  std::vector<std::int32_t> near, near_count;
  bool flat = false;
  std::vector<std::int32_t> cone_stamp;      // per node: the step its perception bounds were computed
  std::vector<double> cos_lo, cos_hi;

  System(const Vec3& lo, const Vec3& hi, double node_cell, double close_cell, double drain_cell, bool is_flat)
      : nodes(lo, hi, node_cell, is_flat), close(lo, hi, close_cell, is_flat), drains(lo, hi, drain_cell, is_flat),
        fresh(lo, hi, drain_cell, is_flat), flat(is_flat), lo_(lo), hi_(hi), scale_(1) {}

  // The grids' cells follow the step's lengths (× σ_T/σ_t, up to 3× the last step's early in a
  // run): a query then scans a few cells, not dozens. Queries answer the same on any cells.
  void rescale(double node_cell, double close_cell, double drain_cell, double k) {
    if (std::abs(std::log(k / scale_)) < std::log(1.25)) return;
    scale_ = k;
    nodes = PointHash(lo_, hi_, node_cell * k, flat);
    close = PointHash(lo_, hi_, close_cell * k, flat);
    drains = PointHash(lo_, hi_, drain_cell * k, flat);
    fresh = PointHash(lo_, hi_, drain_cell * k, flat);  // emptied before every use
    for (std::size_t i = 0; i < pos.size(); ++i) nodes.insert(pos[i], std::int32_t(i)), close.insert(pos[i], std::int32_t(i));
    for (std::size_t d = 0; d < drain.size(); ++d) drains.insert(drain[d], std::int32_t(d));
  }
  Vec3 lo_, hi_;
  double scale_;

  double radiusOf(std::int32_t i) const { return std::pow(rk[std::size_t(i)], 1.0 / kappa); }

  std::int32_t add(const Vec3& p, std::int32_t par, const Vec3& d, double leaf_r, std::int32_t root) {
    const auto id = static_cast<std::int32_t>(pos.size());
    pos.push_back(p);
    dir.push_back(d);
    parent.push_back(par);
    child0.push_back(-1);
    child1.push_back(-1);
    root_of.push_back(root);
    leaf_radius.push_back(leaf_r);
    const double own = std::pow(leaf_r, kappa);
    rk.push_back(own);
    if (par < 0) roots.push_back(id);
    if (par >= 0) {
      // Murray's law in r^κ is additive: the new leaf adds its share to every ancestor, and a
      // leaf that becomes a parent no longer counts its own.
      const double delta = child0[par] < 0 ? own - std::pow(leaf_radius[par], kappa) : own;
      (child0[par] < 0 ? child0[par] : child1[par]) = id;
      for (std::int32_t a = par; a >= 0; a = parent[a]) rk[a] += delta;
    }
    nodes.insert(p, id);
    close.insert(p, id);
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
    fresh.insert(p, id);
  }
  // True if a node lies within r (r at most a few cells of `close`).
  bool nodeWithin(const Vec3& p, double r) const {
    const double r2 = r * r;
    return (r > 2 * close.cell() ? nodes : close).anyNear(p, r, [&](std::int32_t id) {
      const Vec3 v = pos[id] - p;
      return dot(v, v) < r2;
    });
  }
  // Nearest node within r (ties: the smaller id), or -1.
  std::int32_t nearestNode(const Vec3& p, double r) const {
    return nodes.nearest(p, r, [&](std::int32_t id) {
      const Vec3 v = pos[id] - p;
      return dot(v, v);
    });
  }
  // The cached nearest node of drain k, if still exact at `step`.
  bool knowsNearest(std::size_t k, std::int32_t step) const {
    return near[k] != -2 && born[k] == step && near_count[k] == std::int32_t(pos.size());
  }
  bool anyDrainWithin(const Vec3& p, double r) const { return drainWithin(drains, p, r); }
  // Only the drains added since the step began (the others were checked in parallel).
  bool freshDrainWithin(const Vec3& p, double r) const { return drainWithin(fresh, p, r); }
  bool drainWithin(const PointHash& grid, const Vec3& p, double r) const {
    const double r2 = r * r;
    return grid.anyNear(p, r, [&](std::int32_t id) {
      const Vec3 v = drain[id] - p;
      return dot(v, v) < r2;
    });
  }
  // Exact Murray radii from the leaves up (children come after their parent), once at the end.
  void finishRadii() {
    radius.assign(pos.size(), 0);
    for (std::size_t k = pos.size(); k-- > 0;) {
      const auto a = child0[k], b = child1[k];
      if (a < 0) radius[k] = leaf_radius[k];
      else if (b < 0) radius[k] = radius[a];
      else radius[k] = std::pow(std::pow(radius[a], kappa) + std::pow(radius[b], kappa), 1.0 / kappa);
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

class Grower {
 public:
  Grower(const ColonisationOptions& o, GrowthReport& report, ColonisationReport& cr)
      : o_(o), report_(report), cr_(cr), world_(*o.world),
        art_(world_.lo(), world_.hi(), cell(o, 0), cell(o, 1), cell(o, 2), world_.dimension() == 2),
        ven_(world_.lo(), world_.hi(), cell(o, 0), cell(o, 1), cell(o, 2), world_.dimension() == 2) {
    art_.vein = false;
    ven_.vein = true;
    art_.kappa = ven_.kappa = o.murray_exponent;
    symmetric_angle_ = symmetricMurrayAngle(o.murray_exponent);
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
  }

  void run(const ProgressFn& progress) {
    const auto scales = colonisationScales(o_);
    std::size_t t = 0;
    for (const auto& st : o_.stages) {
      for (int s = 0; s < st.steps; ++s, ++t) {
        step(st, scales[t]);
        cr_.nodes_per_step.push_back(std::int64_t(art_.pos.size() + ven_.pos.size()));
        if (progress) progress(std::int64_t(t + 1), std::int64_t(scales.size()));
      }
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
      c = std::min(c, which == 0 ? st.perception_distance / 2 : which == 1 ? st.satisfaction_distance : std::max(st.drain_spacing, st.perception_distance / 2));
    return std::max(c, 1e-6);
  }

  // The centreline a–b inside the world: convex shapes by its end, masks voxel by voxel (every
  // voxel the segment crosses is inside; sampling at fractions of a voxel can cut a corner).
  bool inside(const Vec3& a, const Vec3& b) const {
    if (world_.shape() != DomainShape::Mask) return world_.depth(b) > 0;  // a is a node (or a root on the border)
    return world_.depth(b) > 0 && world_.frame().segmentClear(a, b);
  }

  Vec3 sampleDrain(const ColonisationStage& st, Rng& rng) const {
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
  std::vector<std::pair<std::int32_t, std::int32_t>> assign(System& s, const ColonisationStage& st, double delta) {
    const double half = st.perception_angle * kDeg / 2, cos_half = std::cos(half);
    std::vector<std::int32_t> owner(s.drain.size(), -1);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.drain.size(), 512), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t k = b.begin(); k != b.end(); ++k) owner[k] = s.knowsNearest(k, step_) ? s.near[k] : s.nearestNode(s.drain[k], delta);
    });
    // Perception bounds of the nodes that are nearest to some drain, computed once per step.
    s.cone_stamp.resize(s.pos.size(), -1);
    s.cos_lo.resize(s.pos.size());
    s.cos_hi.resize(s.pos.size());
    std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
    for (std::size_t k = 0; k < s.drain.size(); ++k) {
      const auto j = owner[k];
      if (j < 0) continue;
      if (s.cone_stamp[j] != step_) {
        s.cone_stamp[j] = step_;
        s.cos_lo[j] = s.cos_hi[j] = 2.0;  // perceives nothing
        if (s.child0[j] < 0) {
          s.cos_lo[j] = cos_half;
          s.cos_hi[j] = 1.0;
        } else if (st.lateral && s.child1[j] < 0 && s.parent[j] >= 0) {
          const double alpha = lateralMurrayAngle(s.radiusOf(j), terminal_radius_, o_.murray_exponent);
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
  bool tryAdd(const System& s, const ColonisationStage& st, std::int32_t from, Vec3 dir, double len, Decision& d) const {
    Vec3 p = toShell(st, s.pos[from] + dir * len);
    if (!inside(s.pos[from], p)) {
      ++d.outside;
      return false;
    }
    if (crosses(s, from, s.pos[from], p, terminal_radius_)) {
      ++d.crossing;
      return false;
    }
    d.add[d.added++] = {from, p, unit(p - s.pos[from])};
    return true;
  }

  // Node j's response to the drains it perceives (pairs [a, b)): it reads the step's starting
  // state only, so the nodes decide in parallel.
  Decision decide(const System& s, const ColonisationStage& st, const std::vector<std::pair<std::int32_t, std::int32_t>>& pairs, std::size_t a,
                  std::size_t b, double len) const {
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
        const double alpha_s = symmetric_angle_;
        const Vec3 d1 = e * std::cos(alpha_s) + w * std::sin(alpha_s), d2 = e * std::cos(alpha_s) - w * std::sin(alpha_s);
        if (tryAdd(s, st, j, d1, len, d) && tryAdd(s, st, j, d2, len, d)) {
          d.move = Move::Bifurcation;
          return d;
        }
        d.added = 0;
      }
      Vec3 g = e * st.bias + m * (1 - st.bias);
      if (!(norm(g) > 1e-12)) g = e;
      if (tryAdd(s, st, j, unit(g), len, d)) d.move = Move::Elongation;
    } else if (s.child1[j] < 0) {
      // An inter-node: a lateral branch at the Murray angle, turned toward the drains.
      const double alpha = lateralMurrayAngle(s.radiusOf(j), terminal_radius_, o_.murray_exponent);
      Vec3 w = m - e * dot(m, e);
      if (!(norm(w) > 1e-9)) return d;
      const Vec3 v = e * std::cos(alpha) + unit(w) * std::sin(alpha);
      Vec3 g = v * st.bias + m * (1 - st.bias);
      if (!(norm(g) > 1e-12)) g = v;
      if (tryAdd(s, st, j, unit(g), len, d)) d.move = Move::Lateral;
    }
    return d;
  }

  void grow(System& s, const ColonisationStage& st, double k) {
    const double len = st.step * k, delta = st.perception_distance * k;
    const auto pairs = assign(s, st, delta);
    std::vector<std::size_t> start;
    for (std::size_t a = 0; a < pairs.size(); ++a)
      if (a == 0 || pairs[a].first != pairs[a - 1].first) start.push_back(a);
    start.push_back(pairs.size());
    std::vector<Decision> decisions(start.size() - 1);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, decisions.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t g = r.begin(); g != r.end(); ++g) decisions[g] = decide(s, st, pairs, start[g], start[g + 1], len);
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
        s.add(p.position, p.from, p.direction, terminal_radius_, s.root_of[p.from]);
        max_edge_ = std::max(max_edge_, distance(p.position, s.pos[p.from]));
      }
    }
  }

  // Drains of s within `sat` of one of its nodes are satisfied: removed (an artery's become the
  // veins' CO₂ sources).
  // `delta`: the perception distance, for the nearest vein of each new CO₂ source.
  void satisfy(System& s, double sat, System* co2, int lifetime, double delta) {
    std::vector<char> done(s.drain.size(), 0);
    std::vector<std::int32_t> vein_near(co2 ? s.drain.size() : 0, -2);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, s.drain.size(), 512), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t k = b.begin(); k != b.end(); ++k) {
        done[k] = s.nodeWithin(s.drain[k], sat);
        if (done[k] && co2) vein_near[k] = co2->nearestNode(s.drain[k], delta);
      }
    });
    std::vector<std::int32_t> keep;
    for (std::size_t k = 0; k < s.drain.size(); ++k) {
      if (!done[k]) {
        if (lifetime <= 0 || step_ - s.born[k] + 1 < lifetime) keep.push_back(std::int32_t(k));  // else expired unsatisfied
        continue;
      }
      if (!s.vein) ++cr_.satisfied;
      if (co2) {
        co2->addDrain(s.drain[k], step_, vein_near[k]);
        ++cr_.venous_drains;
      }
    }
    s.keepDrains(keep);
  }

  void step(const ColonisationStage& st, double k) {
    for (System* s : {&art_, &ven_}) s->rescale(cell(o_, 0), cell(o_, 1), cell(o_, 2), k);
    terminal_radius_ = st.terminal_radius * k;
    const double sat = st.satisfaction_distance * k, spacing = st.drain_spacing * k;
    const double co2 = st.co2_distance * k, delta = st.perception_distance * k;
    const bool veins = o_.veins && !ven_.pos.empty();
    // 1. Oxygen drains where the tissue is not yet supplied, apart from each other. Candidate q
    // of step t is drawn from its own stream and tested against the trees and the drains the
    // step began with in parallel; the spacing among this step's drains is kept in draw order.
    enum : char { Supplied = 1, Oxygenated = 2, Drained = 4, NearVeinDrain = 8, NearArteryDrain = 16 };
    candidates_.resize(std::size_t(st.drains_per_step));
    flags_.assign(candidates_.size(), 0);
    art_near_.assign(candidates_.size(), -2);
    ven_near_.assign(candidates_.size(), -2);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates_.size(), 256), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t q = b.begin(); q != b.end(); ++q) {
        Rng rng(o_.seed, o_.sample, Stage::Growth, 1 + (std::uint64_t(step_) << 32) + q);
        const Vec3 p = candidates_[q] = sampleDrain(st, rng);
        // Supplied: an artery within the satisfaction distance; oxygenated: within the CO₂
        // distance. Such tissue makes CO₂, a source for the veins unless a vein drains it.
        // A candidate that may become a drain also finds the node that will perceive it.
        char f = 0;
        if (art_.nodeWithin(p, sat)) {
          f = Supplied;
        } else if (art_.anyDrainWithin(p, spacing)) {
          f = NearArteryDrain | (veins && art_.nodeWithin(p, co2) ? Oxygenated : 0);
        } else {
          const auto j = art_.nearestNode(p, std::max(delta, co2));
          const Vec3 v = j >= 0 ? art_.pos[std::size_t(j)] - p : Vec3(0, 0, 0);
          const double d2 = j >= 0 ? dot(v, v) : INFINITY;
          if (veins && d2 < co2 * co2) f = Oxygenated;
          art_near_[q] = d2 < delta * delta ? j : -1;
        }
        if (veins && (f & (Supplied | Oxygenated))) {
          if (ven_.nodeWithin(p, sat)) f |= Drained;
          else if (ven_.anyDrainWithin(p, spacing)) f |= NearVeinDrain;
          else ven_near_[q] = ven_.nearestNode(p, delta);
        }
        flags_[q] = f;
      }
    });
    art_.fresh.clear();
    ven_.fresh.clear();
    for (std::size_t i = 0; i < candidates_.size(); ++i) {
      const Vec3 p = candidates_[i];
      const char f = flags_[i];
      ++report_.candidates;
      if ((f & (Supplied | Oxygenated)) && !(f & (Drained | NearVeinDrain)) && !ven_.freshDrainWithin(p, spacing)) {
        ven_.addDrain(p, step_, ven_near_[i]);
        ++cr_.venous_drains;
      }
      if (f & Supplied) {
        ++report_.rejected_too_close;
        continue;
      }
      if ((f & NearArteryDrain) || art_.freshDrainWithin(p, spacing)) continue;
      art_.addDrain(p, step_, art_near_[i]);
      ++cr_.arterial_drains;
    }
    // 2. Arteries grow; the drains they reach turn into CO₂ sources too; 3. veins grow to those.
    grow(art_, st, k);
    for (const System* s : {&art_, &ven_})
      for (auto r : s->roots) max_radius_ = std::max(max_radius_, s->radiusOf(r));
    satisfy(art_, sat, veins ? &ven_ : nullptr, st.drain_lifetime, delta);
    if (veins) {
      grow(ven_, st, k);
      satisfy(ven_, sat, nullptr, st.drain_lifetime, delta);
    }
    ++step_;
  }

  const ColonisationOptions& o_;
  GrowthReport& report_;
  ColonisationReport& cr_;
  const GrowthDomain& world_;
  System art_, ven_;
  std::vector<Vec3> candidates_;
  std::vector<char> flags_;
  std::vector<std::int32_t> art_near_, ven_near_;
  double terminal_radius_ = 0, max_edge_ = 0, max_radius_ = 0, symmetric_angle_ = 0;
  std::int32_t step_ = 0;
};

}  // namespace

std::vector<VascularTree> growColonisation(const ColonisationOptions& o, GrowthReport& report, ColonisationReport& cr,
                                           const ProgressFn& progress) {
  Grower g(o, report, cr);
  g.run(progress);
  return g.trees();
}

}  // namespace angiosynth
