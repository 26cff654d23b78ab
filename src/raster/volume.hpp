#pragma once
// A voxel grid in the tree's mm frame and dense volumes on it. Voxel (i,j,k) is centred at
// origin + (i·sx, j·sy, k·sz): `origin_mm` is the centre of voxel (0,0,0).
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/vec3.hpp"

namespace angiosynth {

struct VolumeGrid {
  std::array<std::int32_t, 3> dims{0, 0, 0};
  Vec3 origin_mm;   // centre of voxel (0,0,0)
  Vec3 spacing_mm{1, 1, 1};

  std::int64_t voxelCount() const { return std::int64_t(dims[0]) * dims[1] * dims[2]; }
  std::int64_t flat(std::int64_t i, std::int64_t j, std::int64_t k) const { return i + dims[0] * (j + dims[1] * k); }
  Vec3 centre(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return Vec3(origin_mm.x + i * spacing_mm.x, origin_mm.y + j * spacing_mm.y, origin_mm.z + k * spacing_mm.z);
  }
  // Continuous voxel index of a point (voxel centres at whole numbers).
  Vec3 index(const Vec3& p) const {
    return Vec3((p.x - origin_mm.x) / spacing_mm.x, (p.y - origin_mm.y) / spacing_mm.y, (p.z - origin_mm.z) / spacing_mm.z);
  }
  bool contains(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2];
  }
  bool operator==(const VolumeGrid&) const = default;
};

template <class T>
struct Volume {
  VolumeGrid grid;
  std::vector<T> data;
  Volume() = default;
  explicit Volume(const VolumeGrid& g, T fill = T{}) : grid(g), data(static_cast<std::size_t>(g.voxelCount()), fill) {}
  T& at(std::int64_t i, std::int64_t j, std::int64_t k) { return data[grid.flat(i, j, k)]; }
  const T& at(std::int64_t i, std::int64_t j, std::int64_t k) const { return data[grid.flat(i, j, k)]; }
};

}  // namespace angiosynth
