#pragma once
// Connected components of label volumes, for tests that a rasterised tree is one piece.
#include <cstdint>
#include <queue>
#include <vector>

#include "raster/volume.hpp"

namespace angiosynth::test {

// 6-connected components of the non-zero voxels.
inline int sixConnectedComponents(const Volume<std::uint8_t>& v) {
  const VolumeGrid& g = v.grid;
  std::vector<char> seen(v.data.size(), 0);
  int count = 0;
  for (std::size_t s = 0; s < v.data.size(); ++s) {
    if (!v.data[s] || seen[s]) continue;
    ++count;
    std::queue<std::int64_t> q;
    q.push(std::int64_t(s));
    seen[s] = 1;
    while (!q.empty()) {
      const auto c = q.front();
      q.pop();
      const std::int64_t x = c % g.dims[0], y = (c / g.dims[0]) % g.dims[1], z = c / (std::int64_t(g.dims[0]) * g.dims[1]);
      const std::int64_t d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
      for (const auto& o : d) {
        const std::int64_t X = x + o[0], Y = y + o[1], Z = z + o[2];
        if (!g.contains(X, Y, Z)) continue;
        const auto n = g.flat(X, Y, Z);
        if (v.data[n] && !seen[n]) seen[n] = 1, q.push(n);
      }
    }
  }
  return count;
}

}  // namespace angiosynth::test
