#include "grow/common/chain_trees.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "grow/common/intersections.hpp"
#include "core/segment_grid.hpp"

namespace angiosynth {

double diameterOf(const GrowthDomain& d) {
  switch (d.shape()) {
    case DomainShape::Sphere:
    case DomainShape::Disc: return 2 * d.size();
    case DomainShape::Cube:
    case DomainShape::Square: return d.size();
    case DomainShape::Mask: break;
  }
  const Vec3 e = d.hi() - d.lo();
  return std::max({e.x, e.y, d.dimension() == 2 ? 0.0 : e.z});
}

void flowsAndPressures(VascularTree& t, const PhysicsParameters& p, double leaf_flow) {
  const auto order = t.topDownOrder();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const auto i = *it;
    const auto a = t.child0[i], b = t.child1[i];
    t.terminals[i] = a < 0 ? 1 : t.terminals[a] + (b < 0 ? 0 : t.terminals[b]);
    t.flow[i] = a < 0 ? leaf_flow : t.flow[a] + (b < 0 ? 0 : t.flow[b]);
  }
  for (auto i : order) {
    if (t.isRoot(i)) {
      t.pressure[i] = p.perfusion_pressure;
      t.radius[i] = 0;
      continue;
    }
    const auto up = t.parent[i];
    const double r = t.radius[i];
    t.beta[i] = t.isRoot(up) ? 1.0 : r / t.radius[up];
    const double drop = 8 * p.viscosity * t.length[i] * t.flow[i] / (std::numbers::pi * r * r * r * r);
    t.pressure[i] = t.pressure[up] - (p.drains() ? -drop : drop);
  }
}

// Candidates from a grid of segment boxes; the path is walked up from both segments within
// that budget.
std::vector<std::pair<std::int32_t, std::int32_t>> crossingPairs(const VascularTree& t) {
  Vec3 lo(INFINITY, INFINITY, INFINITY), hi(-INFINITY, -INFINITY, -INFINITY);
  double total = 0;
  std::int64_t segments = 0;
  for (std::int32_t i = 0; i < t.nodeCount(); ++i) {
    const auto& p = t.position[i];
    lo = componentMin(lo, p);
    hi = componentMax(hi, p);
    if (!t.isRoot(i)) total += t.length[i] + 2 * t.maxRadius(i), ++segments;
  }
  std::vector<std::pair<std::int32_t, std::int32_t>> out;
  if (segments == 0) return out;
  // Cells of about twice the mean segment extent.
  SegmentGrid grid(lo, hi, 2 * total / double(segments), hi.z == lo.z);
  for (std::int32_t i = 0; i < t.nodeCount(); ++i)
    if (!t.isRoot(i)) grid.insert(i, t.position[t.parent[i]], t.position[i], t.maxRadius(i));
  // True if x and y are joined along their tree by a path shorter than `budget`.
  const auto joined = [&](std::int32_t x, std::int32_t y, double budget) {
    std::vector<std::pair<std::int32_t, double>> up;  // x's proximal node and its ancestors, with the path to them
    double s = 0;
    for (std::int32_t v = t.parent[x]; v >= 0 && s <= budget; v = t.parent[v]) {
      up.emplace_back(v, s);
      if (v == t.parent[y] || v == y) return true;
      if (t.parent[v] >= 0) s += t.length[v];
    }
    s = 0;
    for (std::int32_t v = t.parent[y]; v >= 0 && s <= budget; v = t.parent[v]) {
      if (v == x) return true;
      for (const auto& [a, sa] : up)
        if (a == v && sa + s <= budget) return true;
      if (t.parent[v] >= 0) s += t.length[v];
    }
    return false;
  };
  for (std::int32_t x = 0; x < t.nodeCount(); ++x) {
    if (t.isRoot(x)) continue;
    const Vec3 &ax = t.position[t.parent[x]], &bx = t.position[x];
    grid.any(ax, bx, t.maxRadius(x), [&](std::int32_t y) {
      if (y <= x) return false;
      if (!capsulesOverlap(ax, bx, t.radius[x], t.position[t.parent[y]], t.position[y], t.radius[y])) return false;
      const double budget = t.radius[x] + t.radius[y];
      if ((t.tree.empty() || t.tree[x] == t.tree[y]) && joined(x, y, budget)) return false;
      out.emplace_back(x, y);
      return false;
    });
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace angiosynth
