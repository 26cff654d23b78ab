#include "raster/ground_truth.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <tuple>

#include <atomic>
#include <cmath>
#include <cstring>
#include <cstdlib>

namespace angiosynth {

std::uint64_t denseRasterBytes(const VolumeGrid& g) {
  const std::uint64_t per_voxel = sizeof(float) /*fraction*/ + 1 /*mask*/ + 1 /*centerline*/ + sizeof(float) /*radius*/ +
                                  sizeof(std::uint32_t) /*instances*/ + 1 /*classes*/ + sizeof(float) /*image*/;
  return static_cast<std::uint64_t>(g.voxelCount()) * per_voxel;
}

namespace {

// What visit(out, index, segment, i, j, k) emits for every voxel (i, j, k) of the whole grid that
// the centreline of segments[index] crosses (segments with a kind), gathered per thread and
// sorted: the result does not depend on the thread count.
template <class T, class Kind, class Visit>
std::vector<T> gatherCrossings(const VascularTree& t, const VolumeGrid& g, std::span<const std::int32_t> segments, const Kind& kind,
                               const Visit& visit) {
  tbb::enumerable_thread_specific<std::vector<T>> local;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, segments.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
    auto& out = local.local();
    for (std::size_t n = r.begin(); n != r.end(); ++n) {
      const std::int32_t s = segments[n];
      if (kind(s) == 0) continue;
      forEachCrossedVoxel(g, t.position[t.parent[s]], t.position[s],
                          [&](std::int64_t i, std::int64_t j, std::int64_t k) { visit(out, n, s, i, j, k); });
    }
  });
  std::vector<T> all;
  for (auto& h : local) all.insert(all.end(), h.begin(), h.end());
  std::sort(all.begin(), all.end());
  return all;
}

// Ordered so that the first crossing of a voxel is the one it keeps.
struct Crossing {
  std::uint64_t voxel;
  std::uint32_t course;       // voxels the segment's centreline crosses
  std::uint32_t radius_bits;  // radii are positive, so their bits order as the floats
  std::int32_t label;
  bool operator<(const Crossing& o) const {
    return std::tie(voxel, course, radius_bits, label) < std::tie(o.voxel, o.course, o.radius_bits, o.label);
  }
};

void fillClassesIn(GroundTruthVolumes& gt, const VascularTree& t, const std::vector<std::uint8_t>& class_of_segment,
                   const std::vector<std::int32_t>* label_of_segment, const VolumeGrid& g, const VoxelWindow& window,
                   std::span<const std::int32_t> segments) {
  gt.classes.reset(gt.instances.grid);
  const std::int64_t n = static_cast<std::int64_t>(gt.instances.data.size());
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, n, 1 << 16), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t v = r.begin(); v < r.end(); ++v) {
      const std::uint32_t s = gt.instances.data[v];
      if (gt.mask.data[v] && s > 0 && s < class_of_segment.size()) gt.classes.data[v] = class_of_segment[s];
    }
  });
  const auto label = [&](std::int32_t s) { return label_of_segment ? (*label_of_segment)[s] : s; };
  const auto kind = [&](std::int32_t s) {
    const auto l = static_cast<std::size_t>(label(s));
    return l < class_of_segment.size() ? class_of_segment[l] : std::uint8_t(0);
  };
  // The voxels where a centreline disagrees with the class (none in a forest of one kind), and
  // each segment's course in voxels of the whole grid; then every centreline crossing those voxels.
  std::vector<std::uint32_t> course(segments.size(), 0);  // one thread per segment
  auto conflicts = gatherCrossings<std::uint64_t>(
      t, g, segments, kind, [&](std::vector<std::uint64_t>& out, std::size_t index, std::int32_t s, std::int64_t i, std::int64_t j, std::int64_t k) {
        ++course[index];
        if (!window.contains(i, j, k)) return;
        const auto v = std::uint64_t(window.flat(i, j, k));
        if (gt.classes.data[v] != kind(s)) out.push_back(v);
      });
  conflicts.erase(std::unique(conflicts.begin(), conflicts.end()), conflicts.end());
  if (conflicts.empty()) return;
  const auto crossings = gatherCrossings<Crossing>(
      t, g, segments, kind, [&](std::vector<Crossing>& out, std::size_t index, std::int32_t s, std::int64_t i, std::int64_t j, std::int64_t k) {
        if (!window.contains(i, j, k)) return;
        const auto v = std::uint64_t(window.flat(i, j, k));
        if (!std::binary_search(conflicts.begin(), conflicts.end(), v)) return;
        const float r = static_cast<float>(t.radius[s]);
        std::uint32_t bits;
        std::memcpy(&bits, &r, sizeof bits);
        out.push_back({v, course[index], bits, label(s)});
      });
  for (std::size_t i = 0; i < crossings.size(); ++i)
    if (i == 0 || crossings[i].voxel != crossings[i - 1].voxel)
      gt.classes.data[crossings[i].voxel] = class_of_segment[std::size_t(crossings[i].label)];
}

void addCenterlinesIn(const VascularTree& t, GroundTruthVolumes& gt, const std::vector<std::int32_t>* label_of_segment, const VolumeGrid& g,
                      const VoxelWindow& window, std::span<const std::int32_t> segments) {
  // Thin vessels stay connected: every voxel a centreline crosses belongs to the mask. Segments
  // run in parallel; every write is order-independent (stores of 1, a maximum for the radius,
  // the lowest segment id for an instance the partial volume did not set), so the result is the
  // same for any thread count, and page faults are taken on both cores. Curves are traced on the
  // whole grid and cut to the window, so a window holds the whole grid's voxels.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, segments.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<std::array<std::int64_t, 3>> curve;
    const auto claim = [&](std::int64_t v, std::int32_t seg) {
      const std::uint32_t s = label_of_segment ? std::uint32_t((*label_of_segment)[seg]) : std::uint32_t(seg);
      std::atomic_ref<std::uint8_t>(gt.mask.data[v]).store(1, std::memory_order_relaxed);
      if (gt.fraction.data[v] >= 0.5f) return;  // labelled by the partial volume
      std::atomic_ref<std::uint32_t> id(gt.instances.data[v]);
      std::uint32_t cur = id.load(std::memory_order_relaxed);
      while ((cur == 0 || s < cur) && !id.compare_exchange_weak(cur, s, std::memory_order_relaxed)) {}
    };
    for (std::size_t n = r.begin(); n != r.end(); ++n) {
      const std::int32_t s = segments[n];
      const Vec3& a = t.position[t.parent[s]];
      const Vec3& b = t.position[s];
      forEachCrossedVoxel(g, a, b, [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        if (window.contains(i, j, k)) claim(window.flat(i, j, k), s);
      });
      if (gt.centerline_connectivity == 6) {
        curve.clear();
        forEachCrossedVoxel(g, a, b, [&](std::int64_t i, std::int64_t j, std::int64_t k) { curve.push_back({i, j, k}); });
      } else {
        centerlineVoxels(g, a, b, curve);
      }
      // Radii are positive, so their bit patterns order like the floats: a maximum on integers.
      // A tapered vessel's radius is the one across from the voxel's centre.
      const double r0 = t.startRadius(s), r1 = t.radius[s];
      const Vec3 ab = b - a;
      const double inv_len2 = dot(ab, ab) > 0 ? 1.0 / dot(ab, ab) : 0.0;
      const float rs = static_cast<float>(r1);
      std::uint32_t rbits;
      std::memcpy(&rbits, &rs, sizeof rbits);
      for (const auto& c : curve) {
        if (!window.contains(c[0], c[1], c[2])) continue;
        const auto v = window.flat(c[0], c[1], c[2]);
        if (r0 != r1) {
          const double f = std::clamp(dot(g.centre(c[0], c[1], c[2]) - a, ab) * inv_len2, 0.0, 1.0);
          const float rl = static_cast<float>(r0 + f * (r1 - r0));
          std::memcpy(&rbits, &rl, sizeof rbits);
        }
        std::atomic_ref<std::uint8_t>(gt.centerline.data[v]).store(1, std::memory_order_relaxed);
        std::atomic_ref<std::uint32_t> rad(*reinterpret_cast<std::uint32_t*>(&gt.radius.data[v]));
        std::uint32_t cur = rad.load(std::memory_order_relaxed);
        while (rbits > cur && !rad.compare_exchange_weak(cur, rbits, std::memory_order_relaxed)) {}
        claim(v, s);
      }
    }
  });
}

}  // namespace

void fillClasses(GroundTruthVolumes& gt, const VascularTree& t, const std::vector<std::uint8_t>& class_of_segment,
                 const std::vector<std::int32_t>* label_of_segment) {
  const VolumeGrid& g = gt.instances.grid;
  fillClassesIn(gt, t, class_of_segment, label_of_segment, g, VoxelWindow::whole(g), treeSegments(t));
}

void fillClasses(GroundTruthVolumes& gt, const VascularTree& t, const std::vector<std::uint8_t>& class_of_segment, const VolumeGrid& grid,
                 const VoxelWindow& window, std::span<const std::int32_t> segments) {
  fillClassesIn(gt, t, class_of_segment, nullptr, grid, window, segments);
}

void centerlineVoxels(const VolumeGrid& g, const Vec3& a_mm, const Vec3& b_mm, std::vector<std::array<std::int64_t, 3>>& out) {
  out.clear();
  const Vec3 a = g.index(a_mm), b = g.index(b_mm);
  std::int64_t p[3], q[3], d[3], s[3];
  for (int ax = 0; ax < 3; ++ax) {
    p[ax] = static_cast<std::int64_t>(std::floor(a[ax] + 0.5));  // voxel i covers [i − ½, i + ½)
    q[ax] = static_cast<std::int64_t>(std::floor(b[ax] + 0.5));
    d[ax] = std::llabs(q[ax] - p[ax]);
    s[ax] = q[ax] >= p[ax] ? 1 : -1;
  }
  // 3D Bresenham along the dominant axis: each step moves to one of the 26 neighbours.
  const int m = d[0] >= d[1] ? (d[0] >= d[2] ? 0 : 2) : (d[1] >= d[2] ? 1 : 2);
  const int u = (m + 1) % 3, v = (m + 2) % 3;
  std::int64_t eu = 2 * d[u] - d[m], ev = 2 * d[v] - d[m];
  for (std::int64_t n = 0; n <= d[m]; ++n) {
    if (g.contains(p[0], p[1], p[2])) out.push_back({p[0], p[1], p[2]});
    if (eu > 0) p[u] += s[u], eu -= 2 * d[m];
    if (ev > 0) p[v] += s[v], ev -= 2 * d[m];
    eu += 2 * d[u];
    ev += 2 * d[v];
    p[m] += s[m];
  }
}

void addCenterlines(const VascularTree& t, GroundTruthVolumes& gt, const std::vector<std::int32_t>* label_of_segment) {
  const VolumeGrid& g = gt.fraction.grid;
  addCenterlinesIn(t, gt, label_of_segment, g, VoxelWindow::whole(g), treeSegments(t));
}

GroundTruthVolumes rasterizeGroundTruth(const VascularTree& t, const VolumeGrid& g, const RasterOptions& opt) {
  return rasterizeGroundTruth(t, g, VoxelWindow::whole(g), treeSegments(t), opt);
}

GroundTruthVolumes rasterizeGroundTruth(const VascularTree& t, const VolumeGrid& g, const VoxelWindow& window, std::span<const std::int32_t> segments,
                                        const RasterOptions& opt) {
  GroundTruthVolumes gt;
  rasterizeGroundTruth(t, g, window, segments, opt, gt);
  return gt;
}

void rasterizeGroundTruth(const VascularTree& t, const VolumeGrid& g, const VoxelWindow& window, std::span<const std::int32_t> segments,
                          const RasterOptions& opt, GroundTruthVolumes& gt) {
  const VolumeGrid local = subGrid(g, window);
  gt.fraction.reset(local);
  gt.instances.reset(local);
  gt.mask.reset(local);
  gt.centerline.reset(local);
  gt.radius.reset(local);
  if (!gt.classes.data.empty()) gt.classes.reset(local);  // fillClasses fills them
  gt.centerline_connectivity = opt.centerline_connectivity;
  // Bricks are disjoint, so the visitor writes from several threads without conflict; only
  // non-zero voxels are written.
  const BrickBins bins = binSegments(t, g, window, segments);
  const auto nb = bins.bricks;
  rasterizeBricks(t, g, bins, opt, [&](std::int64_t brick, const float* f, const std::uint32_t* id) {
    const std::int64_t bx = brick % nb[0], by = (brick / nb[0]) % nb[1], bz = brick / (std::int64_t(nb[0]) * nb[1]);
    for (int k = 0; k < kBrick; ++k)
      for (int j = 0; j < kBrick; ++j)
        for (int i = 0; i < kBrick; ++i) {
          const int v = i + kBrick * (j + kBrick * k);
          const std::int64_t x = bx * kBrick + i, y = by * kBrick + j, z = bz * kBrick + k;
          if (f[v] == 0 || !window.contains(x, y, z) || !g.contains(x, y, z)) continue;
          const auto w = window.flat(x, y, z);
          gt.fraction.data[w] = f[v];
          if (f[v] >= 0.5f) {
            gt.mask.data[w] = 1;
            gt.instances.data[w] = id[v];
          }
        }
  });
  addCenterlinesIn(t, gt, nullptr, g, window, segments);
}

}  // namespace angiosynth
