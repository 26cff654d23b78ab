#pragma once
// A voxel grid in the tree's mm frame and dense volumes on it. Voxel (i,j,k) is centred at
// origin + (i·sx, j·sy, k·sz): `origin_mm` is the centre of voxel (0,0,0).
#include <algorithm>
#include <array>
#include <cstdlib>
#include <new>
#include <cmath>
#include <cstdint>
#include <vector>

#include <sys/mman.h>

#include "core/vec3.hpp"

namespace angiosynth {

struct VolumeGrid {
  std::array<std::int32_t, 3> dims{0, 0, 0};
  Vec3 origin_mm;  // centre of voxel (0,0,0)
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

// The voxels lo <= (i, j, k) < hi of a grid: a chunk of a volume rasterised piece by piece.
struct VoxelWindow {
  std::array<std::int64_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
  static VoxelWindow whole(const VolumeGrid& g) { return VoxelWindow{{0, 0, 0}, {g.dims[0], g.dims[1], g.dims[2]}}; }
  std::int64_t size(int axis) const { return hi[axis] - lo[axis]; }
  std::int64_t voxelCount() const { return size(0) * size(1) * size(2); }
  bool contains(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return i >= lo[0] && j >= lo[1] && k >= lo[2] && i < hi[0] && j < hi[1] && k < hi[2];
  }
  // Index of voxel (i, j, k) of the grid in the window's own volume (x fastest).
  std::int64_t flat(std::int64_t i, std::int64_t j, std::int64_t k) const { return (i - lo[0]) + size(0) * ((j - lo[1]) + size(1) * (k - lo[2])); }
  bool operator==(const VoxelWindow&) const = default;
};

// The grid of a window's voxels: the same spacing, the origin at the centre of voxel lo. Values
// rasterised for the window are computed on the whole grid's voxel centres, so they equal the whole
// grid's voxel for voxel.
inline VolumeGrid subGrid(const VolumeGrid& g, const VoxelWindow& b) {
  VolumeGrid s;
  for (int ax = 0; ax < 3; ++ax) s.dims[ax] = static_cast<std::int32_t>(b.size(ax));
  s.origin_mm = g.centre(b.lo[0], b.lo[1], b.lo[2]);
  s.spacing_mm = g.spacing_mm;
  return s;
}

// Large volumes in transparent huge pages where the system allows it: a voxel read before it is
// written maps the shared zero page, and the write that follows then costs a page fault and a TLB
// flush on every core, per 4 KiB page; per 2 MiB page this is 512 times rarer (the rasteriser's
// centreline pass spent a third of its time there).
inline void adviseHugePages(void* p, std::size_t bytes) {
  constexpr std::size_t kHuge = std::size_t(2) << 20;
  if (bytes < 4 * kHuge) return;
  const auto begin = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const auto end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

// Allocates zeroed memory with calloc and skips value-initialisation, so a mostly empty volume
// costs no time and no resident memory until its voxels are written (the kernel hands out zero
// pages lazily); zero-filling a 512³ float volume otherwise takes most of a second.
template <class T>
struct ZeroAllocator {
  using value_type = T;
  ZeroAllocator() = default;
  template <class U>
  ZeroAllocator(const ZeroAllocator<U>&) {}
  T* allocate(std::size_t n) {
    if (void* p = std::calloc(n, sizeof(T))) {
      adviseHugePages(p, n * sizeof(T));
      return static_cast<T*>(p);
    }
    throw std::bad_alloc();
  }
  void deallocate(T* p, std::size_t) { std::free(p); }
  template <class U>
  void construct(U* p) {}  // the memory is already zero
  template <class U, class... A>
  void construct(U* p, A&&... a) {
    ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
  }
  template <class U>
  bool operator==(const ZeroAllocator<U>&) const {
    return true;
  }
};

template <class T>
using VoxelBuffer = std::vector<T, ZeroAllocator<T>>;

template <class T>
struct Volume {
  VolumeGrid grid;
  VoxelBuffer<T> data;
  Volume() = default;
  // Zero-filled unless `fill` says otherwise.
  explicit Volume(const VolumeGrid& g, T fill = T{}) : grid(g), data(static_cast<std::size_t>(g.voxelCount())) {
    if (fill != T{}) std::fill(data.begin(), data.end(), fill);
  }
  // Zero on grid g, keeping the storage when the voxel count is the same: a volume made afresh for
  // every chunk of a larger one would take a page fault on each of its pages, every time.
  void reset(const VolumeGrid& g) {
    const auto n = static_cast<std::size_t>(g.voxelCount());
    if (data.size() == n)
      std::fill(data.begin(), data.end(), T{});
    else
      data = VoxelBuffer<T>(n);
    grid = g;
  }
  T& at(std::int64_t i, std::int64_t j, std::int64_t k) { return data[grid.flat(i, j, k)]; }
  const T& at(std::int64_t i, std::int64_t j, std::int64_t k) const { return data[grid.flat(i, j, k)]; }
};

}  // namespace angiosynth
