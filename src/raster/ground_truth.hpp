#pragma once
// The tree's ground truth on an image grid: partial-volume fraction, mask, centreline, radius
// and instance labels, all derived from the tree (the single source of truth).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/vascular_tree.hpp"
#include "raster/capsule_rasterizer.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

struct GroundTruthVolumes {
  Volume<float> fraction;            // fraction of each voxel inside the vessels, [0, 1]
  Volume<std::uint8_t> mask;         // fraction >= 0.5, plus every voxel a centreline crosses
  Volume<std::uint8_t> centerline;   // voxel curve of every segment, 26- or 6-connected
  int centerline_connectivity = 26;  // see RasterOptions
  Volume<float> radius;              // mm, on centreline voxels (the thicker vessel at joints)
  Volume<std::uint32_t> instances;   // segment id (= distal node id) on mask voxels, else 0
  // The kind of the vessel on mask voxels (1 artery, 2 vein, further kinds on), else 0: that of
  // the voxel's instance, except on a voxel that a centreline of another kind crosses (see
  // fillClasses).
  Volume<std::uint8_t> classes;
};

// Bytes of all dense channels plus a float image, for the size guard.
std::uint64_t denseRasterBytes(const VolumeGrid& grid);

// Fills gt.classes: class_of_segment[instance] on mask voxels; then every voxel that a
// centreline of tree t crosses with another kind takes the kind of the crossing segment whose
// centreline crosses the fewest voxels (for which the voxel is the largest share of its course),
// then the thinner, then the lower label. Without it a thin vessel running through another
// kind's partial volume loses its course there; two centrelines of different kinds in one voxel
// (thin vessels, closer than a voxel) are the only losses left, shared evenly by the kinds
// rather than always taken from the wider one. Instances keep the partial-volume rule. Segment
// s of t carries label label_of_segment[s] (warped trees), or s.
void fillClasses(GroundTruthVolumes& gt, const VascularTree& t, const std::vector<std::uint8_t>& class_of_segment,
                 const std::vector<std::int32_t>* label_of_segment = nullptr);

GroundTruthVolumes rasterizeGroundTruth(const VascularTree& tree, const VolumeGrid& grid, const RasterOptions& opt);
// The ground truth of the voxels of `window` alone (its lo a multiple of kBrick), on
// subGrid(grid, window), from `segments` (ascending; any superset of those that reach the window):
// voxel for voxel the whole grid's values, so a volume can be made chunk by chunk.
GroundTruthVolumes rasterizeGroundTruth(const VascularTree& tree, const VolumeGrid& grid, const VoxelWindow& window,
                                        std::span<const std::int32_t> segments, const RasterOptions& opt);
// The same into `gt`, whose volumes are reused when they have the window's size (chunk after
// chunk); classes, if gt has them, are zeroed for fillClasses.
void rasterizeGroundTruth(const VascularTree& tree, const VolumeGrid& grid, const VoxelWindow& window, std::span<const std::int32_t> segments,
                          const RasterOptions& opt, GroundTruthVolumes& gt);
// fillClasses for such a window: each centreline's course is counted on the whole grid.
void fillClasses(GroundTruthVolumes& gt, const VascularTree& t, const std::vector<std::uint8_t>& class_of_segment, const VolumeGrid& grid,
                 const VoxelWindow& window, std::span<const std::int32_t> segments);

// The centreline pass: marks centreline (as gt.centerline_connectivity says) and radius, and adds
// to the mask (and, where the partial volume left no label, to the instances) every voxel a
// segment's centreline crosses.
// Instances are segment ids, or label_of_segment[segment] when given.
void addCenterlines(const VascularTree& tree, GroundTruthVolumes& gt, const std::vector<std::int32_t>* label_of_segment);

// The 26-connected voxel curve (3D Bresenham) between the voxels containing a and b (mm),
// clipped to the grid.
void centerlineVoxels(const VolumeGrid& grid, const Vec3& a_mm, const Vec3& b_mm, std::vector<std::array<std::int64_t, 3>>& out);
// Calls f(i, j, k) for every voxel the segment a–b (mm) passes through.
template <class F>
void forEachCrossedVoxel(const VolumeGrid& grid, const Vec3& a_mm, const Vec3& b_mm, F&& f);

}  // namespace angiosynth

#include "core/voxel_traversal.hpp"

namespace angiosynth {

template <class F>
void forEachCrossedVoxel(const VolumeGrid& g, const Vec3& a_mm, const Vec3& b_mm, F&& f) {
  // Shift by ½ so that voxel i covers [i, i+1); clip the segment to the grid box first.
  Vec3 a = g.index(a_mm) + Vec3(0.5, 0.5, 0.5), b = g.index(b_mm) + Vec3(0.5, 0.5, 0.5);
  double t0 = 0, t1 = 1;
  const Vec3 d = b - a;
  for (int ax = 0; ax < 3; ++ax) {
    const double lo = 0, hi = g.dims[ax];
    if (d[ax] == 0) {
      if (a[ax] < lo || a[ax] > hi) return;
      continue;
    }
    double ta = (lo - a[ax]) / d[ax], tb = (hi - a[ax]) / d[ax];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return;
  traverseVoxels(a + d * t0, a + d * t1, g.dims, [&](std::int32_t i, std::int32_t j, std::int32_t k) {
    f(i, j, k);
    return true;
  });
}

}  // namespace angiosynth
