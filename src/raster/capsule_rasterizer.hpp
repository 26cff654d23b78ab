#pragma once
// Partial-volume rasterisation of a tree of capsules (cylinders with spherical caps, so joints
// are seamless). A voxel's value is the fraction of it inside the union of all vessels, from
// S×S×S subvoxel samples. Work is proportional to the voxels near vessels: segments are binned
// into 8³ bricks and TBB runs over non-empty bricks; voxels far from every capsule surface are
// classified 0 or 1 without sampling. Every voxel is computed independently, so the result does
// not depend on the thread count.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/vascular_tree.hpp"
#include "raster/volume.hpp"

namespace angiosynth {

struct RasterOptions {
  int supersampling = 4;  // S: S³ samples per voxel in partially covered voxels
  // The centreline channel: 26 (a thin digital curve per segment, 3D Bresenham) or 6 (every
  // voxel the segment passes through, face-connected, so a tree is one 6-connected component).
  int centerline_connectivity = 26;
};

constexpr int kBrick = 8;  // brick edge in voxels (an OpenVDB leaf node)

// Segments that may touch each brick, in brick order; built once per tree and grid.
struct BrickBins {
  std::array<std::int32_t, 3> bricks{0, 0, 0};
  std::vector<std::int64_t> brick_ids;              // non-empty bricks, ascending
  std::vector<std::vector<std::int32_t>> segments;  // per non-empty brick, ascending ids
};
// Upper bound on the (brick, segment) pairs binSegments collects: the bricks of every capsule's
// bounding box. Cheap (no allocation), so the sparse path can be refused before binning.
double brickPairBound(const VascularTree& tree, const VolumeGrid& g);
BrickBins binSegments(const VascularTree& tree, const VolumeGrid& grid);
// The bins of the bricks inside `window` (its lo a multiple of kBrick), from `segments` (ascending;
// any superset of those that reach the window): the same bins the whole grid's binning holds for
// those bricks, so the window's voxels rasterise to the same values.
BrickBins binSegments(const VascularTree& tree, const VolumeGrid& grid, const VoxelWindow& window, std::span<const std::int32_t> segments);
// The segments (not roots), ascending.
std::vector<std::int32_t> treeSegments(const VascularTree& tree);

// Calls visit(brick_id, fraction[512], instance[512]) for every non-empty brick, in parallel.
// fraction is in [0,1]; instance is the segment id whose capsule surface is deepest around the
// voxel (0 where the fraction is 0). Voxels outside the grid are left 0.
using BrickVisitor = std::function<void(std::int64_t brick, const float* fraction, const std::uint32_t* instance)>;
void rasterizeBricks(const VascularTree& tree, const VolumeGrid& grid, const BrickBins& bins, const RasterOptions& opt, const BrickVisitor& visit);

// Dense fraction and instance volumes.
void rasterizeDense(const VascularTree& tree, const VolumeGrid& grid, const RasterOptions& opt, Volume<float>& fraction,
                    Volume<std::uint32_t>& instances);

}  // namespace angiosynth
