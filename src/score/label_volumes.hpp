#pragma once
// Labelled volumes as the per-class and challenge metrics read them: which values occur, each
// class's voxels within the box where it or its counterpart lies, and which classes touch.
#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <vector>

#include "raster/volume.hpp"

namespace angiosynth {

// Voxels of each value 1 … 255 (index = value).
std::array<std::int64_t, 256> labelCounts(const Volume<std::uint8_t>& classes);

// An inclusive voxel box; empty when lo > hi on an axis.
struct VoxelBox {
  std::array<std::int64_t, 3> lo{0, 0, 0}, hi{-1, -1, -1};
  bool empty() const { return lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]; }
};

// The box of the voxels of each value (index = value) in any of the volumes, grown by `pad`
// voxels and kept within the grid; found in one pass over the volumes.
std::array<VoxelBox, 256> valueBoxes(const std::vector<const Volume<std::uint8_t>*>& volumes, int pad);

// The voxels equal to `value` within the box, as a binary volume of the box's size (the spacing
// kept): distances, thinning and components inside it are those of the whole grid when the box
// holds every such voxel and a voxel of background around them.
Volume<std::uint8_t> valueMask(const Volume<std::uint8_t>& classes, std::uint8_t value, const VoxelBox& box);
// Any volume's voxels within the box.
template <class T>
Volume<T> cropped(const Volume<T>& v, const VoxelBox& box) {
  VolumeGrid g = v.grid;
  for (int a = 0; a < 3; ++a) g.dims[a] = std::int32_t(box.hi[a] - box.lo[a] + 1);
  g.origin_mm = v.grid.centre(box.lo[0], box.lo[1], box.lo[2]);
  Volume<T> out(g);
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) out.at(i, j, k) = v.at(i + box.lo[0], j + box.lo[1], k + box.lo[2]);
  return out;
}

// Which classes touch (26-neighbours, background left out): for each class present, the other
// classes among its voxels' neighbours. Symmetric.
std::map<int, std::set<int>> labelNeighbours(const Volume<std::uint8_t>& classes);

}  // namespace angiosynth
