#pragma once
// Disjoint sets over 0 … n − 1 with path halving; each set's representative is its smallest
// member, so the result does not depend on the order of the joins.
#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace angiosynth {

struct UnionFind {
  std::vector<std::int32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t x) {
    while (parent[std::size_t(x)] != x) x = parent[std::size_t(x)] = parent[std::size_t(parent[std::size_t(x)])];
    return x;
  }
  void unite(std::int32_t a, std::int32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::size_t(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace angiosynth
