#include "grow/bifurcation_optimizer.hpp"

#include <array>

#include "domain/demand_map.hpp"

namespace angiosynth {

BifurcationOptimizer::Subtree BifurcationOptimizer::shortened(std::int32_t s, double l_down) const {
  const auto& t = tree_;
  Subtree v{l_down, kernel_.lengthCost(l_down)};
  if (const auto a = t.child0[s]; a >= 0) {
    const auto b = t.child1[s];
    v.reduced_resistance += 1.0 / (pow4(t.beta[a]) / t.reduced_resistance[a] + pow4(t.beta[b]) / t.reduced_resistance[b]);
    v.cost_ratio += kernel_.radiusCost(t.beta[a]) * t.cost_ratio[a] + kernel_.radiusCost(t.beta[b]) * t.cost_ratio[b];
  }
  return v;
}

double BifurcationOptimizer::cost(std::int32_t s, double l_up, double l_down, double l_term,
                                  std::vector<PathLevel>* record) const {
  const auto& t = tree_;
  const auto& k = kernel_;
  // The old segment s keeps its subtree but now starts at b.
  const auto [R_s, V_s] = shortened(s, l_down);
  const double R_t = l_term, V_t = k.lengthCost(l_term);
  // The new segment from s's proximal node to b, with children s and the terminal.
  auto sp = k.split(t.terminals[s], R_s, 1.0, R_t);
  double R = combinedResistance(l_up, sp, R_s, R_t);
  double V = k.lengthCost(l_up) + k.radiusCost(sp.beta_a) * V_s + k.radiusCost(sp.beta_b) * V_t;
  std::int32_t n = t.terminals[s] + 1;
  if (record) record->push_back({-1, s, -1, sp.beta_a, sp.beta_b, R, V, n});
  std::int32_t below = s;
  for (std::int32_t node = t.parent[s]; node != 0; below = node, node = t.parent[node]) {
    const auto other = t.child0[node] == below ? t.child1[node] : t.child0[node];
    sp = k.split(n, R, t.terminals[other], t.reduced_resistance[other]);
    R = combinedResistance(t.length[node], sp, R, t.reduced_resistance[other]);
    V = k.lengthCost(t.length[node]) + k.radiusCost(sp.beta_a) * V + k.radiusCost(sp.beta_b) * t.cost_ratio[other];
    n = t.terminals[node] + 1;
    if (record) record->push_back({node, below, other, sp.beta_a, sp.beta_b, R, V, n});
  }
  const double r_root = rootRadius(params_, n * params_.terminalFlow(), R);
  return k.radiusCost(r_root) * V;
}

double BifurcationOptimizer::costAt(std::int32_t s, const Vec3& b, const Vec3& term) const {
  return cost(s, distance(tree_.position[tree_.parent[s]], b), distance(b, tree_.position[s]), distance(b, term));
}

bool BifurcationOptimizer::admissible(std::int32_t s, const Vec3& b, const Vec3& term) const {
  const Vec3& p = tree_.position[tree_.parent[s]];
  const Vec3& o = tree_.position[s];
  if (distance(p, b) < min_length_ || distance(b, o) < min_length_ || distance(b, term) < min_length_) return false;
  return map_.segmentClear(p, b) && map_.segmentClear(b, o) && map_.segmentClear(b, term);
}

Connection BifurcationOptimizer::optimise(std::int32_t s, const Vec3& term, int max_iterations) const {
  const std::array<Vec3, 3> ends{tree_.position[tree_.parent[s]], tree_.position[s], term};
  Connection best;
  best.segment = s;
  best.terminal = term;
  // Start at VascuSynth's midpoint, moved a third of the way to the terminal.
  Vec3 b = (ends[0] + ends[1]) * 0.5;
  b = b + (term - b) * (1.0 / 3.0);
  const auto try_point = [&](const Vec3& x) {
    if (!admissible(s, x, term)) return false;
    const double c = costAt(s, x, term);
    if (best.valid && c >= best.cost) return false;
    best.valid = true;
    best.cost = c;
    best.bifurcation = x;
    return true;
  };
  if (!try_point(b)) {
    // The midpoint of s itself only needs the terminal segment to be clear.
    if (!try_point((ends[0] + ends[1]) * 0.5)) return best;
    b = best.bifurcation;
  }
  const double tol = 1e-6 * (distance(ends[0], ends[1]) + distance(ends[1], ends[2]) + 1e-12);
  for (int it = 0; it < max_iterations; ++it) {
    std::array<double, 3> l;
    for (int j = 0; j < 3; ++j) l[j] = std::max(distance(b, ends[j]), min_length_);
    const double c0 = cost(s, l[0], l[1], l[2]);
    Vec3 num;
    double den = 0;
    for (int j = 0; j < 3; ++j) {
      std::array<double, 3> lp = l;
      const double h = 1e-7 * l[j] + 1e-12;
      lp[j] += h;
      const double w = std::max((cost(s, lp[0], lp[1], lp[2]) - c0) / h, 0.0);
      num += ends[j] * (w / l[j]);
      den += w / l[j];
    }
    if (!(den > 0)) break;
    Vec3 next = num / den;
    // Halve the step until the exact cost decreases and the point is admissible.
    bool moved = false;
    for (int half = 0; half < 4 && !moved; ++half) {
      moved = try_point(next);
      next = (next + best.bifurcation) * 0.5;
    }
    if (!moved) break;
    const double step = distance(b, best.bifurcation);
    b = best.bifurcation;
    if (step < tol) break;
  }
  return best;
}

void BifurcationOptimizer::record(Connection& c) const {
  c.path.clear();
  const Vec3& b = c.bifurcation;
  cost(c.segment, distance(tree_.position[tree_.parent[c.segment]], b), distance(b, tree_.position[c.segment]),
       distance(b, c.terminal), &c.path);
  const auto& top = c.path.back();
  c.root_radius = rootRadius(params_, top.terminals * params_.terminalFlow(), top.reduced_resistance);
}

}  // namespace angiosynth
