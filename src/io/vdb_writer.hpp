#pragma once
// Sparse output for volumes too large to hold densely: the rasterizer's bricks (8³, the size of
// an OpenVDB leaf) go straight into OpenVDB grids, so memory follows the vessels, not the box.
#include <cstdint>
#include <filesystem>

#include "core/vascular_tree.hpp"
#include "raster/capsule_rasterizer.hpp"

namespace angiosynth {

// Memory the sparse path needs for these bins (leaves of both grids plus bookkeeping).
std::uint64_t sparseRasterBytes(const BrickBins& bins);

struct VdbReport {
  std::int64_t leaves = 0;
  std::int64_t active_voxels = 0;
};

// Writes `fraction` (FloatGrid, partial volume in [0,1], background 0) and `instances`
// (Int32Grid, segment id on voxels with fraction >= 0.5) with the grid's voxel size and origin
// (world = origin + index × spacing, RAS mm).
VdbReport writeVdb(const std::filesystem::path& file, const VascularTree& tree, const VolumeGrid& grid, const BrickBins& bins,
                   const RasterOptions& opt);

}  // namespace angiosynth
