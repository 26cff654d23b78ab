#include "score/label_volumes.hpp"

#include <algorithm>
#include <cmath>

namespace angiosynth {

std::array<std::int64_t, 256> labelCounts(const Volume<std::uint8_t>& classes) {
  std::array<std::int64_t, 256> n{};
  for (std::uint8_t v : classes.data) ++n[v];
  n[0] = 0;
  return n;
}

std::array<VoxelBox, 256> valueBoxes(const std::vector<const Volume<std::uint8_t>*>& volumes, int pad) {
  std::array<VoxelBox, 256> boxes;
  for (auto& b : boxes) b.lo = {INT64_MAX, INT64_MAX, INT64_MAX}, b.hi = {INT64_MIN, INT64_MIN, INT64_MIN};
  std::array<bool, 256> seen{};
  for (const auto* v : volumes) {
    const VolumeGrid& g = v->grid;
    for (std::int64_t k = 0; k < g.dims[2]; ++k)
      for (std::int64_t j = 0; j < g.dims[1]; ++j)
        for (std::int64_t i = 0; i < g.dims[0]; ++i) {
          const std::uint8_t value = v->at(i, j, k);
          if (!value) continue;
          seen[value] = true;
          VoxelBox& b = boxes[value];
          const std::array<std::int64_t, 3> p{i, j, k};
          for (int a = 0; a < 3; ++a) b.lo[a] = std::min(b.lo[a], p[a]), b.hi[a] = std::max(b.hi[a], p[a]);
        }
  }
  const VolumeGrid& g = volumes.front()->grid;
  for (std::size_t value = 0; value < boxes.size(); ++value) {
    VoxelBox& b = boxes[value];
    if (!seen[value]) {
      b = VoxelBox{};
      continue;
    }
    for (int a = 0; a < 3; ++a) b.lo[a] = std::max<std::int64_t>(0, b.lo[a] - pad), b.hi[a] = std::min<std::int64_t>(g.dims[a] - 1, b.hi[a] + pad);
  }
  return boxes;
}

Volume<std::uint8_t> valueMask(const Volume<std::uint8_t>& classes, std::uint8_t value, const VoxelBox& box) {
  Volume<std::uint8_t> c = cropped(classes, box);
  for (auto& v : c.data) v = v == value;
  return c;
}

std::map<int, std::set<int>> labelNeighbours(const Volume<std::uint8_t>& classes) {
  std::map<int, std::set<int>> out;
  const VolumeGrid& g = classes.grid;
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) {
        const int a = classes.at(i, j, k);
        if (!a) continue;
        out[a];
        // The 13 neighbours ahead in voxel order: each touching pair is met once from each side's turn.
        for (int dz = 0; dz <= 1; ++dz)
          for (int dy = dz ? -1 : 0; dy <= 1; ++dy)
            for (int dx = (dz || dy) ? -1 : 1; dx <= 1; ++dx) {
              const std::int64_t x = i + dx, y = j + dy, z = k + dz;
              if (!g.contains(x, y, z)) continue;
              const int b = classes.at(x, y, z);
              if (b && b != a) out[a].insert(b), out[b].insert(a);
            }
      }
  return out;
}

}  // namespace angiosynth
