#include "grow/common/spread_bifurcation.hpp"

#include <algorithm>
#include <array>

namespace angiosynth {

std::optional<Vec3> spreadBifurcation(const VascularTree& tree, std::int32_t v, double min_ratio) {
  if (tree.parent[v] < 0) return std::nullopt;
  std::array<std::int32_t, 3> segs{v, tree.child0[v], tree.child1[v]};
  std::array<Vec3, 3> far_end{tree.position[tree.parent[v]]};
  for (std::size_t i = 1; i < 3; ++i)
    if (segs[i] >= 0) far_end[i] = tree.position[segs[i]];
  double thickest = 0;
  for (const auto x : segs)
    if (x >= 0) thickest = std::max(thickest, tree.radius[x]);
  constexpr int kSweeps = 16;
  Vec3 q = tree.position[v];
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    bool settled = true;
    for (std::size_t i = 0; i < 3; ++i) {
      if (segs[i] < 0) continue;
      const Vec3 d = q - far_end[i];
      const double len = norm(d);
      if (len >= kSpreadSettled * min_ratio * tree.radius[segs[i]]) continue;
      if (!(len > 0)) return std::nullopt;
      settled = false;
      q = q + d * ((kSpreadLength * min_ratio * tree.radius[segs[i]] - len) / len);
    }
    if (settled) return sweep > 0 && distance(q, tree.position[v]) <= kSpreadLength * min_ratio * thickest ? std::optional<Vec3>(q) : std::nullopt;
  }
  return std::nullopt;
}

}  // namespace angiosynth
