#include "physics/hemodynamics.hpp"

#include <numbers>

namespace angiosynth {

double rootRadius(const PhysicsParameters& p, double root_flow, double root_reduced_resistance) {
  const double dp = std::abs(p.perfusion_pressure - p.terminal_pressure);
  return std::sqrt(std::sqrt(root_flow * 8.0 * p.viscosity / std::numbers::pi * root_reduced_resistance / dp));
}

void solveTree(VascularTree& t, const PhysicsParameters& p) {
  if (t.nodeCount() < 2) return;
  const PowerKernel k(p);
  const auto order = t.topDownOrder();
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
    const auto s = k.split(t.terminals[a], t.reduced_resistance[a], t.terminals[b], t.reduced_resistance[b]);
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
