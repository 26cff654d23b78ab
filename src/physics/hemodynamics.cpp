#include "physics/hemodynamics.hpp"

#include <algorithm>
#include <numbers>
#include <stdexcept>

namespace angiosynth {

MurrayLaw::MurrayLaw(double exponent, const std::vector<double>& band_edges, const std::vector<double>& band_exponents) {
  exponent_[0] = exponent;
  if (band_exponents.empty()) return;
  if (band_exponents.size() != band_edges.size() + 1 || band_exponents.size() > std::size_t(kMaxBands))
    throw std::logic_error("Murray bands: one exponent more than edges, at most 8 bands");
  bands_ = int(band_exponents.size());
  for (int k = 0; k < bands_; ++k) exponent_[k] = band_exponents[k];
  for (int k = 0; k + 1 < bands_; ++k) log_edge_[k] = std::log(band_edges[k]);
}

double rootRadius(const PhysicsParameters& p, double root_flow, double root_reduced_resistance) {
  const double dp = std::abs(p.perfusion_pressure - p.terminal_pressure);
  return std::sqrt(std::sqrt(root_flow * 8.0 * p.viscosity / std::numbers::pi * root_reduced_resistance / dp));
}

double MurrayLaw::parentRadius(double r_a, double r_b) const {
  if (!banded()) {
    const double g = exponent_[0];
    return std::pow(std::pow(r_a, g) + std::pow(r_b, g), 1.0 / g);
  }
  // f(r) = r^γ − r_a^γ − r_b^γ is below 0 at max(r_a, r_b) and above at r_a + r_b for any γ > 1.
  double lo = std::max(r_a, r_b), hi = r_a + r_b;
  for (int k = 0; k < 200 && hi - lo > 1e-16 * hi; ++k) {
    const double r = 0.5 * (lo + hi), g = exponentAt(r);
    (std::pow(r, g) < std::pow(r_a, g) + std::pow(r_b, g) ? lo : hi) = r;
  }
  return 0.5 * (lo + hi);
}

namespace {

// One bottom-up and one top-down pass; `parent_radius`, when given, sets each bifurcation's γ
// (banded law) by its parent's id.
void solvePasses(VascularTree& t, const PhysicsParameters& p, const PowerKernel& k, const std::vector<std::int32_t>& order,
                 const std::vector<double>* parent_radius) {
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const auto i = *it;
    if (i == 0) continue;
    t.length[i] = distance(t.position[t.parent[i]], t.position[i]);
    const auto a = t.child0[i], b = t.child1[i];
    if (a < 0) {
      t.terminals[i] = 1;
      t.reduced_resistance[i] = t.length[i];
      t.cost_ratio[i] = k.lengthCost(t.length[i]);
      continue;
    }
    if (b < 0) {  // a node inside a vessel (trees joined at a terminal): one radius, resistances in series
      t.beta[a] = 1;
      t.terminals[i] = t.terminals[a];
      t.reduced_resistance[i] = t.length[i] + t.reduced_resistance[a];
      t.cost_ratio[i] = k.lengthCost(t.length[i]) + t.cost_ratio[a];
      continue;
    }
    const auto s =
        k.split(t.terminals[a], t.reduced_resistance[a], t.terminals[b], t.reduced_resistance[b], parent_radius ? (*parent_radius)[i] : 0.0);
    t.beta[a] = s.beta_a;
    t.beta[b] = s.beta_b;
    t.terminals[i] = t.terminals[a] + t.terminals[b];
    t.reduced_resistance[i] = combinedResistance(t.length[i], s, t.reduced_resistance[a], t.reduced_resistance[b]);
    t.cost_ratio[i] = k.lengthCost(t.length[i]) + k.radiusCost(s.beta_a) * t.cost_ratio[a] + k.radiusCost(s.beta_b) * t.cost_ratio[b];
  }
  const double q_term = p.terminalFlow();
  const auto root = t.rootSegment();
  t.beta[root] = 1;
  t.pressure[0] = p.perfusion_pressure;
  t.depth[0] = 0;
  // A draining tree (a vein) carries its flow from the terminals to the root: pressure rises downstream.
  const double resistance_factor = (p.drains() ? -8.0 : 8.0) * p.viscosity / std::numbers::pi;
  for (auto i : order) {
    if (i == 0) continue;
    const auto par = t.parent[i];
    t.depth[i] = t.depth[par] + 1;
    t.flow[i] = q_term * t.terminals[i];
    t.radius[i] = i == root ? rootRadius(p, t.flow[i], t.reduced_resistance[i]) : t.radius[par] * t.beta[i];
    t.pressure[i] = t.pressure[par] - t.flow[i] * resistance_factor * t.length[i] / pow4(t.radius[i]);
  }
}

// A radius → γ → radius map that is not a contraction (a steep law) would not settle.
constexpr int kMaxBandPasses = 200;

}  // namespace

int solveTree(VascularTree& t, const PhysicsParameters& p) {
  if (t.nodeCount() < 2) return 0;
  const PowerKernel k(p);
  const auto order = t.topDownOrder();
  if (!k.law().banded()) {
    solvePasses(t, p, k, order, nullptr);
    return 1;
  }
  std::vector<double> radius_used(t.nodeCount());
  for (int pass = 1;; ++pass) {
    for (std::int32_t i = 1; i < t.nodeCount(); ++i) radius_used[i] = t.radius[i];
    solvePasses(t, p, k, order, &radius_used);
    double worst = 0;
    for (std::int32_t i = 1; i < t.nodeCount(); ++i)
      if (t.child0[i] >= 0) worst = std::max(worst, std::abs(k.gammaAt(t.radius[i]) - k.gammaAt(radius_used[i])));
    if (worst <= 1e-13) return pass;
    if (pass == kMaxBandPasses)
      throw std::runtime_error("the radii under the banded Murray exponents did not settle in " + std::to_string(kMaxBandPasses) +
                               " passes (largest change of γ " + std::to_string(worst) + ")");
  }
}

double treeCost(const VascularTree& t, const PhysicsParameters& p) {
  const PowerKernel k(p);
  double c = 0;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i)
    if (!t.isRoot(i)) c += k.lengthCost(t.length[i]) * k.radiusCost(t.radius[i]);
  return c;
}

double treeVolume(const VascularTree& t) {
  double v = 0;
  for (std::int32_t i = 1; i < t.nodeCount(); ++i)
    if (!t.isRoot(i)) v += std::numbers::pi * t.radius[i] * t.radius[i] * t.length[i];
  return v;
}

}  // namespace angiosynth
