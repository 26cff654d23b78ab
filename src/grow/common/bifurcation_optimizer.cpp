#include "grow/common/bifurcation_optimizer.hpp"

#include <algorithm>
#include <array>
#include <optional>
#include <span>

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

// The walk from the new bifurcation to the root behind cost() and summarise(): visit sees each
// level's new values, the new bifurcation's first.
template <class Visit>
double BifurcationOptimizer::walkToRoot(std::int32_t s, double l_up, double l_down, double l_term, Visit&& visit) const {
  const auto& t = tree_;
  const auto& k = kernel_;
  // The old segment s keeps its subtree but now starts at b.
  const auto [R_s, V_s] = shortened(s, l_down);
  const double R_t = l_term, V_t = k.lengthCost(l_term);
  // The new segment from s's proximal node to b, with children s and the terminal.
  // With banded γ the new bifurcation's parent takes s's radius, and each ancestor its own (as last solved).
  auto sp = k.split(t.terminals[s], R_s, 1.0, R_t, t.radius[s]);
  double R = combinedResistance(l_up, sp, R_s, R_t);
  double V = k.lengthCost(l_up) + k.radiusCost(sp.beta_a) * V_s + k.radiusCost(sp.beta_b) * V_t;
  std::int32_t n = t.terminals[s] + 1;
  visit(PathLevel{-1, s, -1, sp.beta_a, sp.beta_b, R, V, n});
  std::int32_t below = s;
  for (std::int32_t node = t.parent[s]; node != 0; below = node, node = t.parent[node]) {
    const auto other = t.child0[node] == below ? t.child1[node] : t.child0[node];
    sp = k.split(n, R, t.terminals[other], t.reduced_resistance[other], t.radius[node]);
    R = combinedResistance(t.length[node], sp, R, t.reduced_resistance[other]);
    V = k.lengthCost(t.length[node]) + k.radiusCost(sp.beta_a) * V + k.radiusCost(sp.beta_b) * t.cost_ratio[other];
    n = t.terminals[node] + 1;
    visit(PathLevel{node, below, other, sp.beta_a, sp.beta_b, R, V, n});
  }
  const double r_root = rootRadius(params_, n * params_.terminalFlow(), R);
  return k.radiusCost(r_root) * V;
}

double BifurcationOptimizer::cost(std::int32_t s, double l_up, double l_down, double l_term, std::vector<PathLevel>* record) const {
  return walkToRoot(s, l_up, l_down, l_term, [&](const PathLevel& level) {
    if (record) record->push_back(level);
  });
}

BifurcationOptimizer::PathSummary BifurcationOptimizer::summarise(std::int32_t s, double l_up, double l_down, double l_term) const {
  PathSummary sum{0, 0, 0, 1, 0, 0};
  sum.cost = walkToRoot(s, l_up, l_down, l_term, [&](const PathLevel& level) {
    if (level.segment < 0) {  // the new bifurcation
      sum.beta_child = level.beta_child, sum.beta_other = level.beta_other;
    } else {
      sum.beta_down *= level.beta_child;  // in the order the recorded path multiplies them, from level 1 up
    }
    sum.terminals = level.terminals;
    sum.reduced_resistance = level.reduced_resistance;
  });
  return sum;
}

double BifurcationOptimizer::costAt(std::int32_t s, const Vec3& b, const Vec3& term) const {
  return cost(s, distance(tree_.position[tree_.parent[s]], b), distance(b, tree_.position[s]), distance(b, term));
}

bool BifurcationOptimizer::admissible(std::int32_t s, const Vec3& b, const Vec3& term) const {
  return admissible(s, b, term, {min_length_, min_length_, min_length_});
}

bool BifurcationOptimizer::admissible(std::int32_t s, const Vec3& b, const Vec3& term, const MinLengths& m) const {
  const Vec3& p = tree_.position[tree_.parent[s]];
  const Vec3& o = tree_.position[s];
  if (distance(p, b) < m[0] || distance(b, o) < m[1] || distance(b, term) < m[2]) return false;
  return !paths_ || (paths_->segmentClear(p, b) && paths_->segmentClear(b, o) && paths_->segmentClear(b, term));
}

std::array<double, 3> BifurcationOptimizer::radiiAt(std::int32_t s, const Vec3& b, const Vec3& term) const {
  // Reused: this runs several times for every trial, and a fresh path grew by reallocation.
  thread_local std::vector<PathLevel> path;
  path.clear();
  const double l_up = std::max(distance(tree_.position[tree_.parent[s]], b), min_length_);
  cost(s, l_up, std::max(distance(b, tree_.position[s]), min_length_), std::max(distance(b, term), min_length_), &path);
  const auto& top = path.back();
  double r = rootRadius(params_, top.terminals * params_.terminalFlow(), top.reduced_resistance);
  for (std::size_t k = path.size() - 1; k >= 1; --k) r *= path[k].beta_child;  // down to the new segment
  return {r, r * path[0].beta_child, r * path[0].beta_other};
}

bool BifurcationOptimizer::keepsLengthRatio(const Connection& c) const {
  return !(length_ratio_ > 0) || admissible(c.segment, c.bifurcation, c.terminal, minimumsFrom(c.segment, c.radii));
}

BifurcationOptimizer::MinLengths BifurcationOptimizer::minimumsFrom(std::int32_t s, const std::array<double, 3>& r) const {
  MinLengths m{min_length_, min_length_, min_length_};
  if (!(length_ratio_ > 0)) return m;
  const double share = radius_share_ ? std::clamp((*radius_share_)[std::size_t(s)], 0.0, 1.0) : 0.0;
  const double split_scale = radius_share_ ? radius_scale_ * std::pow(root_radius_scale_ / radius_scale_, share * share) : radius_scale_;
  for (int j = 0; j < 3; ++j) m[j] = std::max(m[j], length_ratio_ * (j < 2 ? split_scale : radius_scale_) * r[j]);
  if (tree_.parent[s] == 0) m[0] = std::max(m[0], length_ratio_ * root_radius_scale_ * r[0]);
  return m;
}

void BifurcationOptimizer::lengthsFrom(const Vec3& b, const std::array<Vec3, 3>& ends, double (&l)[3]) const {
  for (int j = 0; j < 3; ++j) l[j] = std::max(distance(b, ends[j]), min_length_);
}

Vec3 BifurcationOptimizer::keepLengths(Vec3 b, const std::array<Vec3, 3>& ends, const MinLengths& m) const {
  // Push b out to the minimum length from each end it comes too close to, so that the search
  // slides along the constraint (the optimum often wants b to merge into a node) instead of
  // stopping at it.
  for (int j = 0; j < 3; ++j) {
    const double r = m[j] * (1 + 1e-9);
    const Vec3 d = b - ends[j];
    const double len = norm(d);
    if (len < r && len > 0) b = ends[j] + d * (r / len);
  }
  return b;
}

BifurcationOptimizer::Level0 BifurcationOptimizer::level0(std::int32_t s, double l_up, double l_down, double l_term) const {
  const auto& k = kernel_;
  const auto [R_s, V_s] = shortened(s, l_down);
  const double R_t = l_term, V_t = k.lengthCost(l_term);
  const auto sp = k.split(tree_.terminals[s], R_s, 1.0, R_t, tree_.radius[s]);
  return {combinedResistance(l_up, sp, R_s, R_t), k.lengthCost(l_up) + k.radiusCost(sp.beta_a) * V_s + k.radiusCost(sp.beta_b) * V_t, sp.beta_a,
          sp.beta_b};
}

BifurcationOptimizer::Evaluation BifurcationOptimizer::evaluate(std::int32_t s, const double (&l)[3], bool with_radii) const {
  // β of the path's children, bottom-up: the radii multiply them top-down from the root, in the
  // order radiiAt does, so that both give the same bits. Kept only when the radii are asked for.
  std::vector<double>* betas = nullptr;
  if (with_radii) {
    thread_local std::vector<double> buffer;
    buffer.clear();
    betas = &buffer;
  }
  const auto& t = tree_;
  const auto& k = kernel_;
  const double lambda = params_.cost_radius_exponent;
  const Level0 base = level0(s, l[0], l[1], l[2]);
  double R = base.R, V = base.V;
  double n = t.terminals[s] + 1;
  // Tangents: a = ∂R/∂R0, bR = ∂V/∂R0, cV = ∂V/∂V0 (R does not depend on V0).
  double a = 1, bR = 0, cV = 1;
  std::int32_t below = s;
  for (std::int32_t node = t.parent[s]; node != 0; below = node, node = t.parent[node]) {
    const auto o = t.child0[node] == below ? t.child1[node] : t.child0[node];
    const double R_o = t.reduced_resistance[o], V_o = t.cost_ratio[o];
    const auto sp = k.split(n, R, t.terminals[o], R_o, t.radius[node]);
    const double q = sp.beta_b / sp.beta_a;  // r_o / r_c
    const double u = k.murray(q, t.radius[node]);
    const double D = pow4(sp.beta_a) / R + pow4(sp.beta_b) / R_o;
    const double bc = k.radiusCost(sp.beta_a), bo = k.radiusCost(sp.beta_b);
    // Closed forms: ∂β_c/∂R = β_c·u/(4R(1+u)), ∂β_o/∂R = −β_o/(4R(1+u)), ∂R'/∂R = 1/(R·D·(1+u)).
    const double inv = 1.0 / (4.0 * R * (1.0 + u));
    const double dV_dR = lambda * inv * (bc * V * u - bo * V_o);
    const double dR_dR = 1.0 / (R * D * (1.0 + u));
    if (betas) betas->push_back(sp.beta_a);
    bR = dV_dR * a + bc * bR;
    cV = bc * cV;
    a = dR_dR * a;
    R = t.length[node] + 1.0 / D;
    V = k.lengthCost(t.length[node]) + bc * V + bo * V_o;
    n = t.terminals[node] + 1;
  }
  const double r_root = rootRadius(params_, n * params_.terminalFlow(), R);
  const double rl = k.radiusCost(r_root);
  Evaluation e;
  e.cost = rl * V;
  if (betas) {
    double r = r_root;
    for (auto beta = betas->rbegin(); beta != betas->rend(); ++beta) r *= *beta;
    e.radii = {r, r * base.beta_a, r * base.beta_b};
  }
  const double gR = lambda / 4.0 * e.cost / R * a + rl * bR;  // ∂C/∂R0
  const double gV = rl * cV;                                  // ∂C/∂V0
  // Level 0 depends on the three lengths in O(1): differentiate it numerically.
  for (int j = 0; j < 3; ++j) {
    double lp[3] = {l[0], l[1], l[2]};
    const double h = 1e-6 * l[j] + 1e-12;
    lp[j] += h;
    const Level0 p = level0(s, lp[0], lp[1], lp[2]);
    e.d_length[j] = gR * (p.R - base.R) / h + gV * (p.V - base.V) / h;
  }
  return e;
}

bool BifurcationOptimizer::optimumAtProximalNode(std::int32_t s, const Vec3& term) const {
  const Vec3& x0 = tree_.position[tree_.parent[s]];
  const Vec3& x1 = tree_.position[s];
  const double l1 = distance(x0, x1), l2 = distance(x0, term);
  if (!(l1 > 0) || !(l2 > 0)) return false;
  const double l[3] = {1e-9 * (l1 + l2), l1, l2};
  const Evaluation e = evaluate(s, l);
  const Vec3 pull = (x1 - x0) * (e.d_length[1] / l1) + (term - x0) * (e.d_length[2] / l2);
  // With 1 % to spare: where the pulls nearly balance (a straight segment, a tiny terminal) the
  // cost along the segment is flat, and points beside the node can be cheaper.
  return norm(pull) <= 0.99 * e.d_length[0];
}

Connection BifurcationOptimizer::optimise(std::int32_t s, const Vec3& term, int max_iterations, const Vec3* start) const {
  const std::array<Vec3, 3> ends{tree_.position[tree_.parent[s]], tree_.position[s], term};
  MinLengths m = minimumsFrom(s, {});
  std::optional<Probe> probe;
  if (length_ratio_ > 0) {
    // The minimums come from the radii at the start (the midpoint without one). The walk that
    // gives them also costs that point, which the search reuses when it starts there unmoved.
    const Vec3 at = start ? *start : (ends[0] + ends[1]) * 0.5;
    double l[3];
    lengthsFrom(at, ends, l);
    probe = Probe{at, evaluate(s, l, true)};
    m = minimumsFrom(s, probe->evaluation.radii);
  }
  Connection c = search(s, term, m, max_iterations, start, probe ? &*probe : nullptr);
  // The radii, and so the minimums, move a little with the bifurcation: search again with the
  // larger of the two until the result keeps its own minimums (once or twice at most).
  for (int pass = 0; pass < 3 && c.valid && length_ratio_ > 0; ++pass) {
    const MinLengths at = minimumsFrom(s, c.radii);
    if (admissible(s, c.bifurcation, term, at)) return c;
    for (int j = 0; j < 3; ++j) m[j] = std::max(m[j], at[j] * (1 + 1e-6));
    c = search(s, term, m, max_iterations, start, probe ? &*probe : nullptr);
  }
  if (c.valid && !keepsLengthRatio(c)) c.valid = false;
  return c;
}

Connection BifurcationOptimizer::search(std::int32_t s, const Vec3& term, const MinLengths& m, int max_iterations, const Vec3* given,
                                        const Probe* probe) const {
  const bool with_radii = length_ratio_ > 0;
  const std::array<Vec3, 3> ends{tree_.position[tree_.parent[s]], tree_.position[s], term};
  Connection best;
  best.segment = s;
  best.terminal = term;
  best.min_lengths = m;
  // Start at VascuSynth's midpoint, moved a third of the way to the terminal; fall back to the
  // midpoint itself, whose only new segment is the one to the terminal.
  const Vec3 mid = (ends[0] + ends[1]) * 0.5;
  Vec3 b;
  double l[3];
  Evaluation e{};
  bool have = false;
  const std::array<Vec3, 2> starts{given ? *given : mid + (term - mid) * (1.0 / 3.0), mid};
  for (Vec3 start : std::span(starts.data(), given ? 1 : 2)) {
    if (length_ratio_ > 0) start = keepLengths(start, ends, m);
    if (!admissible(s, start, term, m)) continue;
    double ls[3];
    lengthsFrom(start, ends, ls);
    const Evaluation es = probe && probe->point == start ? probe->evaluation : evaluate(s, ls, with_radii);
    if (have && es.cost >= e.cost) continue;
    have = true;
    b = start;
    e = es;
    std::copy(ls, ls + 3, l);
  }
  if (!have) return best;
  best.valid = true;
  best.cost = e.cost;
  best.bifurcation = b;
  const double tol = 1e-6 * (distance(ends[0], ends[1]) + distance(ends[1], ends[2]) + 1e-12);
  // Gradient ∇C = Σ_j w_j (b − x_j)/l_j with w_j = ∂C/∂l_j, and the Weiszfeld metric 1/Σ(w_j/l_j).
  const auto gradient = [&](const Evaluation& ev, const Vec3& x, const double(&lx)[3], double* metric) {
    Vec3 g;
    double den = 0;
    for (int j = 0; j < 3; ++j) {
      const double w = ev.d_length[j] / lx[j];
      g += (x - ends[j]) * w;
      den += std::max(w, 0.0);
    }
    if (metric) *metric = den > 0 ? 1.0 / den : 0.0;
    return g;
  };
  double h0 = 0;
  Vec3 g = gradient(e, b, l, &h0);
  if (!(h0 > 0)) {
    best.cost = e.cost;
    best.bifurcation = b;
    best.radii = e.radii;
    return best;
  }
  // BFGS from the Weiszfeld metric (whose plain step b − h0·∇C is the Weiszfeld point), with
  // backtracking that also steps back from points that cross an obstacle.
  double H[3][3] = {{h0, 0, 0}, {0, h0, 0}, {0, 0, h0}};
  for (int it = 0; it < max_iterations; ++it) {
    Vec3 dir(-(H[0][0] * g.x + H[0][1] * g.y + H[0][2] * g.z), -(H[1][0] * g.x + H[1][1] * g.y + H[1][2] * g.z),
             -(H[2][0] * g.x + H[2][1] * g.y + H[2][2] * g.z));
    // On a minimum-length sphere a step into it would only be pushed back out and the line search
    // fail, leaving the point unpolished or to the compass polish: slide along the sphere instead.
    for (int j = 0; j < 3; ++j) {
      const Vec3 out = b - ends[j];
      const double len = norm(out);
      if (!(len > 0) || len > m[j] * (1 + 1e-6)) continue;
      const double inward = dot(dir, out / len);
      if (inward < 0) dir = dir - out / len * inward;
    }
    const double slope = dot(g, dir);
    if (!(slope < 0)) break;
    bool moved = false;
    Vec3 next;
    double ln[3];
    Evaluation en{};
    for (double t = 1.0; t > 1e-3 && !moved; t *= 0.5) {
      next = keepLengths(b + dir * t, ends, m);
      if (!admissible(s, next, term, m)) continue;
      lengthsFrom(next, ends, ln);
      en = evaluate(s, ln, with_radii);
      moved = en.cost < e.cost + 1e-4 * t * slope || (t < 0.2 && en.cost < e.cost);
    }
    if (!moved) break;
    const Vec3 gn = gradient(en, next, ln, nullptr);
    const Vec3 sv = next - b, yv = gn - g;
    b = next;
    e = en;
    g = gn;
    std::copy(ln, ln + 3, l);
    if (norm(sv) < tol) {
      best.converged = true;
      break;
    }
    const double sy = dot(sv, yv);
    if (sy > 1e-300) {
      // H ← (I − ρ s yᵀ) H (I − ρ y sᵀ) + ρ s sᵀ
      const double rho = 1.0 / sy;
      const double s_[3] = {sv.x, sv.y, sv.z}, y_[3] = {yv.x, yv.y, yv.z};
      double Hy[3], yHy = 0;
      for (int i = 0; i < 3; ++i) {
        Hy[i] = H[i][0] * y_[0] + H[i][1] * y_[1] + H[i][2] * y_[2];
        yHy += y_[i] * Hy[i];
      }
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) H[i][k] += rho * ((1 + rho * yHy) * s_[i] * s_[k] - Hy[i] * s_[k] - s_[i] * Hy[k]);
    }
  }
  best.cost = e.cost;
  best.bifurcation = b;
  best.radii = e.radii;
  return best;
}

void BifurcationOptimizer::polish(Connection& c) const {
  if (c.converged) return;  // a stationary point of the smooth cost: nothing to escape
  // Axis moves of shrinking size, at most kPolishEvaluations trials.
  constexpr int kPolishEvaluations = 48;
  const Vec3& term = c.terminal;
  const std::int32_t s = c.segment;
  const std::array<Vec3, 3> ends{tree_.position[tree_.parent[s]], tree_.position[s], term};
  Vec3 b = c.bifurcation;
  double l[3];
  lengthsFrom(b, ends, l);
  double best_cost = c.cost;
  double step = 0.25 * std::min({l[0], l[1], l[2]});
  const double tol = 1e-6 * (distance(ends[0], ends[1]) + distance(ends[1], ends[2]) + 1e-12);
  const double min_step = 1e-3 * min_length_ + tol;
  for (int evals = 0; evals < kPolishEvaluations && step > min_step;) {
    bool improved = false;
    for (int d = 0; d < 6 && evals < kPolishEvaluations; ++d) {
      Vec3 next = b;
      (d / 2 == 0 ? next.x : (d / 2 == 1 ? next.y : next.z)) += (d % 2 ? -step : step);
      next = keepLengths(next, ends, c.min_lengths);
      if (!admissible(s, next, term, c.min_lengths)) continue;
      ++evals;
      double ln[3];
      lengthsFrom(next, ends, ln);
      const double cn = cost(s, ln[0], ln[1], ln[2]);
      if (cn < best_cost) {
        b = next;
        best_cost = cn;
        improved = true;
      }
    }
    if (!improved) step *= 0.5;
  }
  if (length_ratio_ > 0 && !(b == c.bifurcation)) c.radii = radiiAt(s, b, term);
  c.bifurcation = b;
  c.cost = best_cost;
}

void BifurcationOptimizer::record(Connection& c) const {
  c.path.clear();
  const Vec3& b = c.bifurcation;
  cost(c.segment, distance(tree_.position[tree_.parent[c.segment]], b), distance(b, tree_.position[c.segment]), distance(b, c.terminal), &c.path);
  const auto& top = c.path.back();
  c.root_radius = rootRadius(params_, top.terminals * params_.terminalFlow(), top.reduced_resistance);
}

}  // namespace angiosynth
